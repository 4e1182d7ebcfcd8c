#pragma once
// A node's output directory: the files each node owns, and the rule that a run never mixes
// with an earlier one (an earlier run's files are refused, or cleared with --overwrite).
#include <nlohmann/json.hpp>

#include <filesystem>
#include <string>
#include <vector>

namespace bouncefit {

// The files (and folders) each node writes into --out DIR (docs/FORMATS.md).
const std::vector<std::string>& CaptureOutputFiles();  // track.csv, session.lcm, waveform.csv
const std::vector<std::string>& DetectOutputFiles();   // peaks.csv, impacts.csv, calibration.json, summary.json
const std::vector<std::string>& FitOutputFiles();      // fit.jsonl, coefficients.json, simulated.csv, fitted_ball/, ...
// Every file a run writes (the three nodes' and the report's).
std::vector<std::string> RunOutputFiles();

// Creates `dir` for a node that writes `owned` into it. Where any of `clear` (a superset of
// `owned`, e.g. every run file) is already there: overwrite false throws std::runtime_error
// ("DIR holds an earlier run (peaks.csv, ...): --overwrite clears it, or choose another
// --out"); overwrite true removes them first.
void ClaimOutputDir(const std::filesystem::path& dir, const std::vector<std::string>& clear,
                    bool overwrite);

// Removes `files` from `dir` (what a run wrote before it was refused), quietly.
void RemoveOutputFiles(const std::filesystem::path& dir, const std::vector<std::string>& files);

// Writes JSON through a temporary file renamed over `path`: a reader never sees half a file.
void WriteJsonAtomically(const std::filesystem::path& path, const nlohmann::json& j);

}  // namespace bouncefit
