#pragma once
// One drop as the fit sees it: every apex seen or heard, by bounce index, and the start the
// simulation runs from among them with the heights (and flights) to match after it.
//
// Any apex is a state the simulation can start from: the ball at that height, at rest
// vertically. The start is bounce 0 (the release) when it begins a run of rebounds, else
// the first apex of the longest unbroken run of apexes at least min_bounce_height_m high;
// the apexes after it are r_1..r_k.
#include <cmath>
#include <map>
#include <vector>

#include "fit/restitution_points.h"
#include "model/ball_model.h"

namespace bouncefit {

// A drop kept for the final fits that follow (fitted jointly with the next drops).
struct KeptDrop {
  double drop_height_m = 0;
  std::vector<double> heights_m, flights_s;
  std::vector<double> sigmas_m;  // the start's, then the heights'
  int start_bounce = 0;
};

class RecordedDrop {
 public:
  struct Apex {
    double height_m = 0, sigma_m = 0, impact_before_s = 0, apex_s = std::nan("");
  };

  // Apexes lower than min_bounce_height_m are not fitted; default_sigma_m stands for a
  // height's unknown uncertainty.
  RecordedDrop(double min_bounce_height_m, double default_sigma_m);

  void Clear();
  // Records apex `bounce` (a later one of the same bounce replaces it: a revision) and
  // chooses the start again.
  void Add(int bounce, const Apex& apex);

  int start_bounce() const { return start_bounce_; }
  double drop_height_m() const { return drop_height_m_; }  // the start's height (0: none)
  int last_bounce() const { return start_bounce_ + static_cast<int>(heights_.size()); }
  // r_1.. above the minimum height.
  const std::vector<double>& fitted_heights() const { return fitted_heights_; }
  // Flight times of the fitted arcs (impact before arc i+1 minus impact before arc i; NaN
  // where either is unknown; all NaN when their median is more than 20% off the flights the
  // heights give: impacts timed on another clock than the heights were measured with).
  const std::vector<double>& fitted_flights() const { return fitted_flights_; }
  // The recorded flights over those the heights give when fitted_flights() drops them for
  // it (NaN: used, or none).
  double flight_clock_ratio() const { return flight_clock_ratio_; }
  bool CanFit() const { return drop_height_m_ > 0 && !fitted_heights_.empty(); }
  // The start apex to the impact after it (seconds on the impacts' clock; NaN: unknown).
  double StartFall() const;
  // RMS of the fitted heights' uncertainties (default_sigma_m when none gives one).
  double MeasurementSigma() const;
  // This drop as a joint fit keeps it (CanFit() must hold).
  KeptDrop Keep() const;

 private:
  void ChooseStart();
  void MeasureFlights();

  double min_bounce_height_m_, default_sigma_m_;
  std::map<int, Apex> apexes_;
  int start_bounce_ = 0;
  double drop_height_m_ = 0;
  std::vector<double> heights_;   // index i: bounce start+i+1
  std::vector<double> sigmas_;
  std::vector<double> impacts_before_;  // index i: the impact starting bounce i+1's arc
  std::vector<double> fitted_heights_, fitted_flights_;
  double flight_clock_ratio_ = std::nan("");
};

// Every drop's restitution points (in the order given), the air's drag from `values`'s drag
// coefficient times air_per_m_per_cd (0: without drag).
std::vector<RestitutionPoint> DropsRestitution(const std::vector<KeptDrop>& drops,
                                               const CoefficientValues& values, double air_per_m_per_cd,
                                               double default_sigma_m);

}  // namespace bouncefit
