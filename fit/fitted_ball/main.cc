// fitted_ball H: the fitted ball dropped from H metres (its bottom above the floor, at rest)
// onto the fit's floor, one run as `bouncefit simulate` does it; prints the bounce heights
// in metres, one per line, down to 1 cm.
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>

#include "fitted_ball.h"

int main(int argc, char** argv) {
  if (argc == 2 && (std::strcmp(argv[1], "--help") == 0 || std::strcmp(argv[1], "-h") == 0)) {
    std::printf("usage: fitted_ball H\n"
                "Drops the fitted ball from H metres (its bottom above the floor, at rest) and\n"
                "prints its bounce heights in metres, one per line (down to 1 cm).\n%s\n",
                fitted_ball::Summary());
    return 0;
  }
  if (argc != 2) {
    std::fprintf(stderr, "fitted_ball: error: expected one drop height in metres (see --help)\n");
    return 2;
  }
  char* end = nullptr;
  const double h = std::strtod(argv[1], &end);
  if (end == argv[1] || *end != '\0' || !std::isfinite(h) || !(h > 0) || !(h < 100)) {
    std::fprintf(stderr, "fitted_ball: error: drop height '%s' is not a number of metres in (0, 100)\n",
                 argv[1]);
    return 2;
  }
  bouncefit::SimulationOptions options;
  options.drop_height_m = h;
  const bouncefit::SimulationResult r =
      bouncefit::SimulateSoftBallDrop(fitted_ball::Config(), fitted_ball::Ball(), options);
  if (!r.ok) {
    std::fprintf(stderr, "fitted_ball: error: simulation failed: %s\n", r.failure.c_str());
    return 1;
  }
  for (double height : r.bounce_heights_m) std::printf("%.9f\n", height);
  return 0;
}
