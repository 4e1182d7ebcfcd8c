// The fit session's final fit: the thorough search at the end of a drop, its safety checks
// and its free-running check (fit/fit_session.h).
#include "fit/fit_session.h"

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cmath>
#include <limits>
#include <future>
#include <set>
#include <thread>
#include <stdexcept>

#include <Eigen/Dense>

#include "fit/drop_ensemble.h"
#include "fit/fit_session_helpers.h"
#include "fit/fit_timeline.h"
#include "fit/least_squares_search.h"
#include "fit/live_step.h"
#include "fit/nlopt_search.h"
#include "fit/paper_search.h"
#include "fit/restitution_fit.h"

namespace bouncefit {

using namespace fit_session_detail;

FitProblem FitSession::WithSafety(FitProblem p) const {
  if (!config_.safe_search || config_.safe_drops_m.empty()) return p;
  const BallModel* model = p.model;
  // Whole drops, until the ball settles: the stored airball goes through the floor near
  // rest, 2 s after a 0.3 m drop, and a set that survives a 2 m drop's first two bounces
  // may still go through later. The fitted drop is checked to rest as well (the search's own
  // runs stop at the last recorded bounce). One thread: the starts keep the cores busy.
  std::vector<double> heights = config_.safe_drops_m;
  heights.push_back(p.simulation.drop_height_m);
  const double min_bounce = config_.safe_min_bounce_m;
  p.safety = [model, heights, min_bounce](const CoefficientValues& v) {
    return UnsafeDrop(*model, v, heights, 1, 0, min_bounce);
  };
  p.safety_simulations = static_cast<int>(heights.size());
  return p;
}

SearchResult FitSession::FinalSearch(int lead_n, int budget, const SearchOptions& options) const {
  const std::vector<CoefficientSpec> lead = FirstSpecs(initial_live_order_, lead_n);
  SearchOptions lo = options;
  lo.max_evaluations = budget / 10;
  LiveStepOptions ls;
  ls.rounds = 4;
  const SearchResult lr =
      LiveStep(WithSafety(MakeProblem(lead, final_start_)), final_start_, lo, ls);
  const CoefficientValues start = lr.evaluations > 0 ? lr.values : final_start_;
  SearchOptions o = options;
  o.max_evaluations = std::max(1, budget - lr.evaluations);
  const FitProblem p = WithSafety(MakeProblem(FreeSpecs(), start));
  SearchResult r = config_.method == "paper" ? PaperSearch(p, start, o) : NloptSearch(p, start, o);
  r.evaluations += lr.evaluations;
  r.safety_checks += lr.safety_checks;
  r.rejected_unsafe += lr.rejected_unsafe;
  return r;
}

FitUpdate FitSession::FinalUpdate(const CancelToken* cancel) {
  const auto t0 = std::chrono::steady_clock::now();
  // From the start of the drop (the table, or the previous drop's final fit), not from the
  // per-bounce updates': which of those finished depends on timing, and on chaotic heights a
  // different start is a different answer. The same peaks give the same final fit.
  // Several starts, best kept: each first does what the per-bounce updates do,
  // deterministically (Gauss-Newton rounds on the 2, 3, 4... most influential coefficients),
  // then the thorough search. On chaotic heights one search's answer is one draw.
  const int starts = std::max(1, config_.final_starts);
  const int k = static_cast<int>(FittedHeights().size());
  // The budget holds everything: the searches, the Jacobian (2 runs per coefficient + 2)
  // and the free-running check (one run per ensemble member), so progress never passes it.
  const int after_search = AfterSearchSimulations();
  const int budget = std::max(1, (config_.max_evaluations_final - after_search) / starts);
  SearchOptions o;
  o.threads = config_.threads;
  o.simulations = &simulations_;
  o.cancel = cancel;
  if (config_.target_rms_fraction > 0) o.target_rms_m = config_.target_rms_fraction * drop_height_m_;
  FitProblem restitution_problem;
  const bool restitution = UsesRestitutionLaw();
  SearchResult restitution_result;
  std::vector<HeldCoefficient> held;
  if (restitution) restitution_result = FinalRestitutionSearch(budget * starts, o, &restitution_problem, &held);
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
      running.push_back(std::async(std::launch::async, [&, lead_n] { return FinalSearch(lead_n, budget, one); }));
    for (size_t i = 0; i < running.size(); ++i) results[i] = running[i].get();
  } else {
    for (size_t i = 0; i < leads.size(); ++i) {
      results[i] = FinalSearch(leads[i], budget, o);
      if (cancel && cancel->cancelled()) break;  // cut short
    }
  }
  SearchResult r;
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
  r.wall_time_s = Seconds(t0);
  r.cancelled = r.cancelled || (cancel && cancel->cancelled());
  const FitProblem p = restitution ? restitution_problem : MakeProblem(FreeSpecs(), r.values);
  if (r.evaluations > 0) current_ = r.values;
  if (r.evaluations > 0 && !r.cancelled) final_start_ = r.values;
  // Uncertainty from the Jacobian at the answer (its own budget: 2 runs per coefficient).
  std::vector<std::vector<double>> jac;
  int extra = 0;
  if (!r.cancelled && !(cancel && cancel->cancelled())) {
    SearchOptions jo = o;
    jo.max_evaluations = 2 * static_cast<int>(p.free.size()) + 2;
    jo.target_rms_m = 0;
    FitObjective jf(p, jo);
    jac = HeightsJacobian(jf, r.values);
    extra = jf.evaluations();
    if (jf.cancelled()) jac.clear();
  }
  if (jac.empty()) jac = r.jacobian;
  // Live updates try the most sensitive coefficients first.
  if (!jac.empty()) {
    std::vector<std::pair<double, std::string>> effect;
    for (size_t j = 0; j < p.free.size(); ++j) {
      double e = 0;
      for (const auto& row : jac) e = std::max(e, std::abs(row[j]));
      effect.emplace_back(-e, p.free[j].name);
    }
    std::stable_sort(effect.begin(), effect.end());
    live_order_.clear();
    for (const auto& [e, name] : effect) live_order_.push_back(name);
  }
  FitUpdate u = Finish(p, r, true, jac, extra, Seconds(t0), model_);
  // The law's coefficients stage 1 held: at a bound (an answer, one-sided), the preset's
  // value (a flat direction), or the data's (a flat direction the preset fits worse).
  for (const HeldCoefficient& h : held) {
    for (auto& c : u.coefficients) {
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
        if (!Contains(u.unidentified, c.name)) u.unidentified.push_back(c.name);
      }
    }
    u.held.push_back(h.name + " " + h.why);
  }
  u.safety_checks = r.safety_checks;
  u.rejected_unsafe = r.rejected_unsafe;
  if (!r.failure.empty() && !r.cancelled)  // every point the search tried failed or was unsafe
    u.warning = "no usable coefficient set found: " + r.failure;
  if (!(cancel && cancel->cancelled())) CheckFreeRun(p, &u);
  // The bounces' own restitution: its scatter between bounces and between drops widens the
  // law's sigmas, and drops that disagree beyond it are no answer (one ball, one floor).
  u.restitution_points = RestitutionPoints(u.values);
  u.restitution = CheckRestitution(u.restitution_points);
  for (auto& c : u.coefficients) {
    if (!c.identifiable || !std::isfinite(c.sigma) || !(c.sigma > 0) || !c.bound.empty()) continue;
    double wider = c.sigma;
    if (c.name == "rebound_restitution" || c.name == "restitution") wider = std::max(wider, u.restitution.sigma_e0);
    if ((c.name == "rebound_restitution_per_mps" || c.name == "restitution_per_mps") &&
        std::isfinite(u.restitution.sigma_k))
      wider = std::max(wider, u.restitution.sigma_k);
    // The covariance (what `predict` spreads) widens with it, its correlations kept.
    const auto it = std::find(u.covariance_names.begin(), u.covariance_names.end(), c.name);
    if (it != u.covariance_names.end()) {
      const size_t i = static_cast<size_t>(it - u.covariance_names.begin());
      const double f = wider / c.sigma;
      for (size_t j = 0; j < u.covariance.size(); ++j) {
        u.covariance[i][j] *= f;
        u.covariance[j][i] *= f;
      }
    }
    c.sigma = wider;
  }
  // An answer only when the fitted ball's heights are within the gate.
  if (!u.recorded_m.empty()) {
    const double highest = *std::max_element(u.recorded_m.begin(), u.recorded_m.end());
    const double limit = std::max(config_.answer_floor_m, config_.answer_fraction * highest);
    if (!r.failure.empty() && !r.cancelled)
      u.no_answer = u.warning;
    else if (!u.restitution.drops_agree)
      u.no_answer = DropsDisagreement(u.restitution);
    else if (!(u.residual_m <= limit))
      u.no_answer = fmt::format(
          "the fitted ball's heights are {:.1f} mm RMS from the recorded ones, more than {:.1f} mm (the "
          "larger of {:.1f} mm and {:.3g}% of the highest apex)",
          1000 * u.residual_m, 1000 * limit, 1000 * config_.answer_floor_m, 100 * config_.answer_fraction);
    else
      u.no_answer = DropOutsideItsGate(u, config_.answer_floor_m, config_.answer_fraction);
  }
  u.wall_time_s = Seconds(t0);
  return u;
}

std::string DropOutsideItsGate(const FitUpdate& u, double floor_m, double fraction) {
  const std::vector<FitDropSlice> slices = FitDropSlices(u);  // this drop's, then each kept drop's
  if (slices.size() < 2 || u.simulated_m.size() != u.recorded_m.size()) return "";
  for (size_t k = 0; k < slices.size(); ++k) {
    const auto from = u.recorded_m.begin() + static_cast<long>(slices[k].first);
    const std::vector<double> rec(from, from + static_cast<long>(slices[k].count));
    const auto sim_from = u.simulated_m.begin() + static_cast<long>(slices[k].first);
    const std::vector<double> sim(sim_from, sim_from + static_cast<long>(slices[k].count));
    if (rec.empty()) continue;
    const double rms = RmsResidual(rec, sim);
    const double limit = std::max(floor_m, fraction * *std::max_element(rec.begin(), rec.end()));
    if (rms <= limit) continue;
    const size_t number = k == 0 ? slices.size() : k;  // in time: the kept drops, then this one
    return fmt::format(
        "drop {} of {}: the fitted ball's heights are {:.1f} mm RMS from its recorded ones, more than {:.1f} mm "
        "(the larger of {:.1f} mm and {:.3g}% of its highest apex): one ball's coefficients do not describe "
        "every drop",
        number, slices.size(), 1000 * rms, 1000 * limit, 1000 * floor_m, 100 * fraction);
  }
  return "";
}

std::vector<RestitutionPoint> FitSession::RestitutionPoints(const CoefficientValues& values) const {
  double cd = 0;
  for (const char* name : {"drag", "drag_coefficient"})
    if (values.count(name)) cd = values.at(name);
  const double c = config_.air_per_m_per_cd * cd;
  std::vector<RestitutionPoint> out;
  int drops = 0;
  auto add = [&](const KeptDrop& d) {
    std::vector<double> apexes{d.drop_height_m};
    apexes.insert(apexes.end(), d.heights_m.begin(), d.heights_m.end());
    const auto points = MeasureRestitution(apexes, d.sigmas_m, c, drops, d.start_bounce, config_.default_sigma_m);
    out.insert(out.end(), points.begin(), points.end());
    drops += !points.empty();
  };
  for (const KeptDrop& d : kept_) add(d);
  if (CanFit()) add(ThisDrop());
  return out;
}

bool FitSession::UsesRestitutionLaw() const {
  if (config_.impact != "restitution" || !quick_model_) return false;
  for (const auto& s : model_.Coefficients())
    if (s.name == "rebound_restitution") return true;
  return false;
}

int FitSession::AfterSearchSimulations() const {
  const int drops = 1 + static_cast<int>(kept_.size());
  return 2 * static_cast<int>(FreeSpecs().size()) + 2 +
         drops * std::max(1, config_.ensemble_members) + 1 +
         static_cast<int>(config_.safe_drops_m.size());
}

int FitSession::FinalBudget() const {
  if (!UsesRestitutionLaw()) return config_.max_evaluations_final;
  const RestitutionFitOptions ro;
  const int search = std::min(ro.max_evaluations, config_.max_evaluations_final - AfterSearchSimulations());
  // Stage 1's point-mass runs (microseconds each) are not counted: they are not the wait.
  return std::max(1, search) + AfterSearchSimulations();
}

SearchResult FitSession::FinalRestitutionSearch(int budget, const SearchOptions& options,
                                               FitProblem* p, std::vector<HeldCoefficient>* held) const {
  RestitutionFitOptions ro;
  ro.segments = config_.objective == "segments";
  ro.max_evaluations = std::min(budget, ro.max_evaluations);
  ro.measurement_sigma_m = MeasurementSigma();
  const RestitutionFit rf =
      FitRestitutionCurve(WithSafety(MakeProblem(FreeSpecs(), final_start_)), *quick_model_, options, ro);
  std::vector<std::string> fitted;
  for (const std::string name : {"rebound_restitution", "rebound_restitution_per_mps", "drag"})
    if (std::none_of(rf.held.begin(), rf.held.end(), [&](const HeldCoefficient& h) { return h.name == name; }))
      fitted.push_back(name);
  *p = MakeProblem(FirstSpecs(fitted, static_cast<int>(fitted.size())), rf.soft.values);
  *held = rf.held;
  return rf.soft;
}

void FitSession::CheckFreeRun(const FitProblem& p, FitUpdate* u) {
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
    simulations_ += one.simulations;
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
    simulations_ += n;
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
