#include "fit/final_fit.h"

#include <algorithm>
#include <cmath>
#include <future>
#include <limits>
#include <thread>

#include "fit/drop_ensemble.h"
#include "fit/live_step.h"
#include "fit/nlopt_search.h"
#include "fit/paper_search.h"
#include "fit/sensitivity.h"

namespace bouncefit {

namespace {

void AddWarning(FitUpdate* u, const std::string& warning) {
  u->warning += (u->warning.empty() ? "" : "; ") + warning;
}

}  // namespace

FinalFit::FinalFit(const BallModel& model, const BallModel* quick_model, const FitSessionConfig& config,
                   const RecordedDrop& drop, const std::vector<KeptDrop>& kept, const DropProblems& problems,
                   CoefficientValues start, std::vector<std::string> lead_order)
    : model_(model),
      quick_model_(quick_model),
      config_(config),
      drop_(drop),
      kept_(kept),
      problems_(problems),
      start_(std::move(start)),
      lead_order_(std::move(lead_order)) {}

int FinalFit::AfterSearchSimulations() const {
  const int drops = 1 + static_cast<int>(kept_.size());
  return 2 * static_cast<int>(FreeCoefficients(model_, config_).size()) + 2 +
         drops * std::max(1, config_.ensemble_members) + 1 + static_cast<int>(config_.safe_drops_m.size());
}

int FinalFit::Budget() const {
  if (!UsesRestitutionLaw(config_, model_, quick_model_)) return config_.max_evaluations_final;
  const RestitutionFitOptions ro;
  const int search = std::min(ro.max_evaluations, config_.max_evaluations_final - AfterSearchSimulations());
  // Stage 1's point-mass runs (microseconds each) are not counted: they are not the wait.
  return std::max(1, search) + AfterSearchSimulations();
}

SearchResult FinalFit::StartSearch(int lead_n, int budget, const SearchOptions& options) const {
  const std::vector<CoefficientSpec> free = FreeCoefficients(model_, config_);
  const std::vector<CoefficientSpec> lead = FirstCoefficients(free, lead_order_, lead_n);
  SearchOptions lo = options;
  lo.max_evaluations = budget / 10;
  LiveStepOptions ls;
  ls.rounds = 4;
  const SearchResult lr = LiveStep(problems_.WithSafety(problems_.Make(lead, start_)), start_, lo, ls);
  const CoefficientValues start = lr.evaluations > 0 ? lr.values : start_;
  SearchOptions o = options;
  o.max_evaluations = std::max(1, budget - lr.evaluations);
  const FitProblem p = problems_.WithSafety(problems_.Make(free, start));
  SearchResult r = config_.method == "paper" ? PaperSearch(p, start, o) : NloptSearch(p, start, o);
  r.evaluations += lr.evaluations;
  r.safety_checks += lr.safety_checks;
  r.rejected_unsafe += lr.rejected_unsafe;
  return r;
}

SearchResult FinalFit::RestitutionSearch(int budget, const SearchOptions& options, FitProblem* p,
                                         std::vector<HeldCoefficient>* held) const {
  const std::vector<CoefficientSpec> free = FreeCoefficients(model_, config_);
  RestitutionFitOptions ro;
  ro.segments = config_.objective == "segments";
  ro.max_evaluations = std::min(budget, ro.max_evaluations);
  ro.measurement_sigma_m = drop_.MeasurementSigma();
  const RestitutionFit rf =
      FitRestitutionCurve(problems_.WithSafety(problems_.Make(free, start_)), *quick_model_, options, ro);
  std::vector<std::string> fitted;
  for (const std::string name : {"rebound_restitution", "rebound_restitution_per_mps", "drag"})
    if (std::none_of(rf.held.begin(), rf.held.end(), [&](const HeldCoefficient& h) { return h.name == name; }))
      fitted.push_back(name);
  *p = problems_.Make(FirstCoefficients(free, fitted, static_cast<int>(fitted.size())), rf.soft.values);
  *held = rf.held;
  return rf.soft;
}

FinalSearchResult FinalFit::Search(const CancelToken* cancel, std::atomic<int>* simulations) {
  // From the start of the drop (the table, or the previous drop's final fit), not from the
  // per-bounce updates': which of those finished depends on timing, and on chaotic heights a
  // different start is a different answer. The same peaks give the same final fit.
  // Several starts, best kept: each first does what the per-bounce updates do,
  // deterministically (Gauss-Newton rounds on the 2, 3, 4... most influential coefficients),
  // then the thorough search. On chaotic heights one search's answer is one draw.
  const int starts = std::max(1, config_.final_starts);
  const int k = static_cast<int>(drop_.fitted_heights().size());
  // The budget holds everything: the searches, the Jacobian (2 runs per coefficient + 2)
  // and the free-running check (one run per ensemble member), so progress never passes it.
  const int after_search = AfterSearchSimulations();
  const int budget = std::max(1, (config_.max_evaluations_final - after_search) / starts);
  SearchOptions o;
  o.threads = config_.threads;
  o.simulations = simulations;
  o.cancel = cancel;
  if (config_.target_rms_fraction > 0) o.target_rms_m = config_.target_rms_fraction * drop_.drop_height_m();
  FinalSearchResult out;
  const bool restitution = UsesRestitutionLaw(config_, model_, quick_model_);
  SearchResult restitution_result;
  if (restitution) restitution_result = RestitutionSearch(budget * starts, o, &out.problem, &out.held);
  // The starts' leads: 2, 3, 4... coefficients, never more than the bounces.
  std::vector<int> leads;
  for (int start_index = 0; start_index < starts && !restitution; ++start_index) {
    const int lead_n = std::max(1, std::min(2 + start_index, k));
    leads.push_back(lead_n);
    if (lead_n >= k) break;  // no other lead
  }
  // The starts are independent: on several cores they run at once, each on one thread (a
  // serial BOBYQA uses one core; three starts on two cores finish in 1.5 starts' time, not
  // 3). Each start is deterministic on its own, so the answer does not depend on the cores.
  std::vector<SearchResult> results(leads.size());
  const int threads = config_.threads > 0 ? config_.threads
                                          : std::max(1, static_cast<int>(std::thread::hardware_concurrency()));
  if (threads > 1 && leads.size() > 1) {
    SearchOptions one = o;
    one.threads = std::max(1, threads / static_cast<int>(leads.size()));
    std::vector<std::future<SearchResult>> running;
    for (int lead_n : leads)
      running.push_back(std::async(std::launch::async, [&, lead_n] { return StartSearch(lead_n, budget, one); }));
    for (size_t i = 0; i < running.size(); ++i) results[i] = running[i].get();
  } else {
    for (size_t i = 0; i < leads.size(); ++i) {
      results[i] = StartSearch(leads[i], budget, o);
      if (cancel && cancel->cancelled()) break;  // cut short
    }
  }
  SearchResult& r = out.result;
  int evaluations = 0, checks = 0, rejected = 0;
  for (size_t i = 0; i < results.size(); ++i) {
    evaluations += results[i].evaluations;
    checks += results[i].safety_checks;
    rejected += results[i].rejected_unsafe;
    if (i == 0 || (results[i].evaluations > 0 && results[i].objective < r.objective))
      r = std::move(results[i]);
  }
  if (restitution) {
    r = std::move(restitution_result);
    evaluations = r.evaluations;
    checks = r.safety_checks;
    rejected = r.rejected_unsafe;
  }
  r.evaluations = evaluations;
  r.safety_checks = checks;
  r.rejected_unsafe = rejected;
  r.cancelled = r.cancelled || (cancel && cancel->cancelled());
  if (!restitution) out.problem = problems_.Make(FreeCoefficients(model_, config_), r.values);
  const FitProblem& p = out.problem;
  if (r.evaluations > 0 && !r.cancelled) start_ = r.values;
  // Uncertainty from the Jacobian at the answer (its own budget: 2 runs per coefficient).
  if (!r.cancelled && !(cancel && cancel->cancelled())) {
    SearchOptions jo = o;
    jo.max_evaluations = 2 * static_cast<int>(p.free.size()) + 2;
    jo.target_rms_m = 0;
    FitObjective jf(p, jo);
    out.jacobian = HeightsJacobian(jf, r.values);
    out.jacobian_evaluations = jf.evaluations();
    if (jf.cancelled()) out.jacobian.clear();
  }
  if (out.jacobian.empty()) out.jacobian = r.jacobian;
  return out;
}

void FinalFit::Check(const FinalSearchResult& s, const CancelToken* cancel, std::atomic<int>* simulations,
                     FitUpdate* u) const {
  const SearchResult& r = s.result;
  // The law's coefficients stage 1 held: at a bound (an answer, one-sided), the preset's
  // value (a flat direction), or the data's (a flat direction the preset fits worse).
  for (const HeldCoefficient& h : s.held) {
    for (auto& c : u->coefficients) {
      if (c.name != h.name) continue;
      c.value = h.value;
      c.note = h.why;
      if (h.kind == HeldCoefficient::Kind::kBound || h.kind == HeldCoefficient::Kind::kTimed) {
        c.identifiable = true;  // an answer, measured: at a bound (one-sided) or by the fall's timing
        c.sigma = h.sigma;
        c.bound = h.bound;
      } else {
        c.identifiable = false;
        c.sigma = std::numeric_limits<double>::quiet_NaN();
        if (std::find(u->unidentified.begin(), u->unidentified.end(), c.name) == u->unidentified.end())
          u->unidentified.push_back(c.name);
      }
    }
    u->held.push_back(h.name + " " + h.why);
  }
  u->safety_checks = r.safety_checks;
  u->rejected_unsafe = r.rejected_unsafe;
  if (!r.failure.empty() && !r.cancelled)  // every point the search tried failed or was unsafe
    u->warning = "no usable coefficient set found: " + r.failure;
  if (!(cancel && cancel->cancelled())) CheckFreeRun(s.problem, simulations, u);
  // The bounces' own restitution: its scatter between bounces and between drops widens the
  // law's sigmas, and drops that disagree beyond it are no answer (one ball, one floor).
  std::vector<KeptDrop> drops = kept_;
  if (drop_.CanFit()) drops.push_back(drop_.Keep());
  u->restitution_points = DropsRestitution(drops, u->values, config_.air_per_m_per_cd, config_.default_sigma_m);
  u->restitution = CheckRestitution(u->restitution_points);
  for (auto& c : u->coefficients) {
    if (!c.identifiable || !std::isfinite(c.sigma) || !(c.sigma > 0) || !c.bound.empty()) continue;
    double wider = c.sigma;
    if (c.name == "rebound_restitution" || c.name == "restitution") wider = std::max(wider, u->restitution.sigma_e0);
    if ((c.name == "rebound_restitution_per_mps" || c.name == "restitution_per_mps") &&
        std::isfinite(u->restitution.sigma_k))
      wider = std::max(wider, u->restitution.sigma_k);
    // The covariance (what `predict` spreads) widens with it, its correlations kept.
    const auto it = std::find(u->covariance_names.begin(), u->covariance_names.end(), c.name);
    if (it != u->covariance_names.end()) {
      const size_t i = static_cast<size_t>(it - u->covariance_names.begin());
      const double f = wider / c.sigma;
      for (size_t j = 0; j < u->covariance.size(); ++j) {
        u->covariance[i][j] *= f;
        u->covariance[j][i] *= f;
      }
    }
    c.sigma = wider;
  }
}

void FinalFit::CheckFreeRun(const FitProblem& p, std::atomic<int>* simulations, FitUpdate* u) const {
  // The free-running drop at the answer: one run exactly as `simulate` does it (so the export
  // reproduces these heights), and the ensemble around it, the honest error bar.
  DropEnsembleOptions eo;
  eo.members = std::max(1, config_.ensemble_members);
  eo.threads = config_.threads;
  // Each drop of a joint fit from its own height, its bounces in its own slots.
  DropEnsemble e;
  e.ok = true;
  for (size_t d = 0; d < p.Drops() && e.ok; ++d) {
    SimulationOptions drop = p.simulation;
    drop.drop_height_m = p.DropHeight(d);
    const size_t n = p.DropStart(d + 1) - p.DropStart(d);
    if (d > 0) {
      const std::vector<double> mine(p.recorded_m.begin() + static_cast<long>(p.DropStart(d)),
                                     p.recorded_m.begin() + static_cast<long>(p.DropStart(d + 1)));
      drop.duration_s = config_.duration_margin * FreeFallApexTime(drop.drop_height_m, mine, static_cast<int>(n)) + 0.2;
      drop.max_bounces = static_cast<int>(n);
    }
    const DropEnsemble one = SimulateDropEnsemble(model_, u->values, drop, eo);
    *simulations += one.simulations;
    u->evaluations += one.simulations;
    if (!one.ok) {
      e.ok = false;
      e.failure = one.failure;
      break;
    }
    auto take = [n](std::vector<double>* to, const std::vector<double>& from) {
      for (size_t i = 0; i < n; ++i) to->push_back(i < from.size() ? from[i] : 0.0);
    };
    take(&e.single_m, one.single_m);
    take(&e.mean_m, one.mean_m);
    take(&e.sd_m, one.sd_m);
  }
  if (!e.ok) {  // simulated_m stays the search's own run at the answer (what simulate gives)
    AddWarning(u, "a perturbed free-running drop diverges: " + e.failure);
    return;
  }
  if (!config_.safe_drops_m.empty()) {
    const std::string unsafe =
        UnsafeDrop(model_, u->values, config_.safe_drops_m, config_.threads, 0, config_.safe_min_bounce_m);
    const int n = static_cast<int>(config_.safe_drops_m.size());
    *simulations += n;
    u->evaluations += n;
    if (!unsafe.empty()) AddWarning(u, "the fitted ball " + unsafe);
  }
  auto first_k = [&](const std::vector<double>& v) {
    std::vector<double> out(p.recorded_m.size(), 0.0);
    for (size_t i = 0; i < out.size() && i < v.size(); ++i) out[i] = v[i];
    return out;
  };
  u->simulated_m = first_k(e.single_m);
  u->residual_m = RmsResidual(p.recorded_m, u->simulated_m);
  if (config_.ensemble_members > 0) {
    u->free_run_mean_m = first_k(e.mean_m);
    u->free_run_sd_m = first_k(e.sd_m);
    u->free_run_residual_m = RmsResidual(p.recorded_m, u->free_run_mean_m);
  }
}

}  // namespace bouncefit
