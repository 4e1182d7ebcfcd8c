#pragma once
// What a bouncefit command's exit status means (README "Exit status"): one meaning each.
namespace bouncefit {

enum ExitStatus : int {
  kExitAnswer = 0,        // an answer was written: a final fit, or the peaks with --no-fit
  kExitError = 1,         // an error (a file that cannot be read or written, a failed source)
  kExitBadFlags = 2,      // a wrong flag, or one the measurement contradicts
  kExitNoBounce = 3,      // no bounce found (no ball in view, or it never bounced)
  kExitNoFit = 4,         // bounces found, but no fit came of them
  kExitInterrupted = 130, // stopped by SIGINT or SIGTERM, after writing what was recorded
};

}  // namespace bouncefit
