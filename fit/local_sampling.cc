#include "fit/local_sampling.h"

#include <algorithm>
#include <random>

namespace bouncefit {

int LocalSampling(FitObjective& f, const std::vector<size_t>& active, std::vector<double>* x,
                  const LocalSamplingOptions& o) {
  if (active.empty() || f.stopped()) return 0;
  const int lambda = o.batch > 0 ? o.batch : std::max(4, 2 * f.threads());
  std::mt19937 rng(o.seed);
  std::normal_distribution<double> normal(0.0, 1.0);
  double sigma = o.initial_sigma;
  double incumbent = f.Evaluate(*x).objective;  // cached when the search came from there
  int improved = 0;
  for (int batch = 0; !f.stopped() && (o.max_batches <= 0 || batch < o.max_batches); ++batch) {
    std::vector<std::vector<double>> candidates(static_cast<size_t>(lambda), *x);
    for (auto& c : candidates)
      for (size_t j : active) c[j] = std::clamp(c[j] + sigma * normal(rng), 0.0, 1.0);
    const auto results = f.EvaluateBatch(candidates);
    size_t best = results.size();
    for (size_t i = 0; i < results.size(); ++i)
      if (!results[i].skipped && results[i].objective < incumbent &&
          (best == results.size() || results[i].objective < results[best].objective))
        best = i;
    if (best < results.size()) {
      incumbent = results[best].objective;
      *x = candidates[best];
      sigma = std::min(o.max_sigma, sigma * o.grow);
      ++improved;
    } else {
      sigma = std::max(o.min_sigma, sigma * o.shrink);
    }
  }
  return improved;
}

}  // namespace bouncefit
