#pragma once
// Small helpers the fit session's two files share (fit_session.cc, fit_session_final.cc).
#include <chrono>
#include <cmath>
#include <string>
#include <vector>

#include "fit/fit_session.h"

namespace bouncefit::fit_session_detail {

inline double Seconds(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

inline void AddWarning(FitUpdate* u, const std::string& warning) {
  u->warning += (u->warning.empty() ? "" : "; ") + warning;
}

inline bool Contains(const std::vector<std::string>& v, const std::string& s) {
  return std::find(v.begin(), v.end(), s) != v.end();
}



}  // namespace bouncefit::fit_session_detail
