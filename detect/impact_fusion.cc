#include "detect/impact_fusion.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>

namespace bouncefit {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// Rise time to the apex of height h with drag k (closed forms of v' = -g - k v^2 and
// v' = g - k v^2 on the way down).
double RiseTime(double h, double g, double k) {
  if (k <= 0) return std::sqrt(2 * h / g);
  return std::atan(std::sqrt(std::expm1(2 * k * h))) / std::sqrt(g * k);
}
double FallTime(double h, double g, double k) {
  if (k <= 0) return std::sqrt(2 * h / g);
  return std::acosh(std::exp(k * h)) / std::sqrt(g * k);
}

// For each seen impact, the heard one nearest to seen + offset within the tolerance
// (-1: none), one-to-one, in time order.
std::vector<int> Pair(const std::vector<double>& heard, const std::vector<double>& seen,
                      double offset, double tol, double* residual_sum) {
  std::vector<int> pair(seen.size(), -1);
  std::vector<bool> used(heard.size(), false);
  *residual_sum = 0;
  for (size_t v = 0; v < seen.size(); ++v) {
    const double want = seen[v] + offset;
    int best = -1;
    for (size_t a = 0; a < heard.size(); ++a)
      if (!used[a] && std::abs(heard[a] - want) <= tol &&
          (best < 0 || std::abs(heard[a] - want) < std::abs(heard[best] - want)))
        best = static_cast<int>(a);
    if (best >= 0) {
      used[best] = true;
      pair[v] = best;
      *residual_sum += std::abs(heard[best] - want);
    }
  }
  return pair;
}

int Count(const std::vector<int>& pair) {
  return static_cast<int>(std::count_if(pair.begin(), pair.end(), [](int p) { return p >= 0; }));
}

// The longest chain of clicks with flights shrinking like a bounce train's (indexes into t,
// ascending). Clicks just after an impact are skipped as its echoes.
std::vector<int> LongestBounceTrain(const std::vector<double>& t, const ImpactFusionConfig& c) {
  std::vector<int> best;
  const size_t n = std::min<size_t>(t.size(), 400);
  for (size_t i = 0; i < n; ++i)
    for (size_t j = i + 1; j < n; ++j) {
      std::vector<int> chain = {static_cast<int>(i), static_cast<int>(j)};
      double flight = t[j] - t[i], ratio = -1;
      for (size_t k = j + 1; k < n; ++k) {
        const double f = t[k] - t[chain.back()];
        const double q = f / flight;
        if (f < c.lone_train_echo_s) continue;  // an echo of the last impact
        if (q < c.lone_train_min_ratio || q > c.lone_train_max_ratio) break;
        if (ratio > 0 && std::abs(q - ratio) > c.lone_train_ratio_step) break;
        chain.push_back(static_cast<int>(k));
        flight = f, ratio = q;
      }
      if (chain.size() > best.size()) best = chain;
    }
  return best;
}

FusedImpact HeardOnly(const AudioImpact& a, double offset_s) {
  FusedImpact h;
  h.t_s = a.t_s - offset_s;
  h.source = ImpactSource::kAudio;
  h.strength = a.strength;
  h.confidence = a.confidence;
  h.video_t_s = kNaN;
  h.audio_t_s = a.t_s;
  return h;
}

// How close a seen impact must be to a heard one to be that impact: a quarter of the flight
// around it, or a frame period and the tolerance (a picture times an impact to about a
// frame), at most 0.4 of the flight.
double MergeTolerance(double flight, const ImpactFusionConfig& c) {
  return std::min(0.4 * flight, std::max(0.25 * flight, c.frame_period_s + c.match_tolerance_s));
}

// The shortest gap from impact i to its neighbours in im (times t_s, in order).
double FlightAround(const std::vector<FusedImpact>& im, size_t i, bool both_only) {
  double flight = 1e300;
  for (size_t j = i; j-- > 0;)
    if (!both_only || im[j].source == ImpactSource::kBoth) {
      flight = std::min(flight, im[i].t_s - im[j].t_s);
      break;
    }
  for (size_t j = i + 1; j < im.size(); ++j)
    if (!both_only || im[j].source == ImpactSource::kBoth) {
      flight = std::min(flight, im[j].t_s - im[i].t_s);
      break;
    }
  return flight;
}

// Seen-only impacts near a heard one are that impact, timed poorly by the picture. Near one
// already paired: the picture saw one impact twice (a small arc split by a noisy sample), a
// duplicate, dropped. Near an unpaired click: they pair.
void MergeSeenIntoHeard(const std::vector<AudioImpact>& heard, std::vector<bool>* used,
                        const ImpactFusionConfig& c, FusionResult* r) {
  auto& im = r->impacts;  // the seen impacts, in order; paired ones kBoth
  for (size_t i = 0; i < im.size(); ++i) {
    if (im[i].source != ImpactSource::kBoth) continue;
    const double tol = MergeTolerance(FlightAround(im, i, true), c);
    for (size_t j = 0; j < im.size(); ++j)
      if (im[j].source == ImpactSource::kVideo && !std::isnan(im[j].t_s) &&
          std::abs(im[j].video_t_s - im[i].t_s) <= tol) {
        r->merged_seen.push_back(im[j].video_t_s);
        im[j].t_s = kNaN;
      }
  }
  std::erase_if(im, [](const FusedImpact& v) { return std::isnan(v.t_s); });
  for (size_t i = 0; i < im.size(); ++i) {
    if (im[i].source != ImpactSource::kVideo) continue;
    const double tol = MergeTolerance(FlightAround(im, i, false), c);
    int nearest = -1;
    for (size_t a = 0; a < heard.size(); ++a) {
      const double d = std::abs(heard[a].t_s - r->offset_s - im[i].video_t_s);
      if (!(*used)[a] && d <= tol &&
          (nearest < 0 || d < std::abs(heard[nearest].t_s - r->offset_s - im[i].video_t_s)))
        nearest = static_cast<int>(a);
    }
    if (nearest < 0) continue;
    (*used)[nearest] = true;
    const AudioImpact& a = heard[nearest];
    im[i].source = ImpactSource::kBoth;
    im[i].t_s = a.t_s - r->offset_s;
    im[i].audio_t_s = a.t_s;
    im[i].strength = a.strength;
    im[i].confidence = a.confidence;
  }
  std::stable_sort(im.begin(), im.end(),
                   [](const FusedImpact& a, const FusedImpact& b) { return a.t_s < b.t_s; });
}

// A gap between two impacts longer than a bounce train allows (its flights shrink) misses
// an impact: unpaired clicks inside it that continue the train are those impacts, heard
// only. The train is followed forward from the flight before the gap, or, for the first
// gap, backward from the flight after it (flights growing back in time).
void FillGapsWithHeard(const std::vector<AudioImpact>& heard, std::vector<bool>* used,
                       const ImpactFusionConfig& c, FusionResult* r) {
  auto& im = r->impacts;
  std::vector<FusedImpact> added;
  for (size_t i = 0; i + 1 < im.size(); ++i) {
    const double begin = im[i].t_s, end = im[i + 1].t_s;
    if (i >= 1) {
      double last = begin, flight = begin - im[i - 1].t_s;
      if (end - last <= c.train_growth * flight) continue;
      for (size_t a = 0; a < heard.size(); ++a) {
        const double t = heard[a].t_s - r->offset_s;
        if ((*used)[a] || t <= last) continue;
        if (t >= end - c.train_min_ratio * flight) break;
        const double f = t - last;
        if (f < c.train_min_ratio * flight) continue;  // an echo or a stray sound
        if (f > c.train_growth * flight) break;
        (*used)[a] = true;
        added.push_back(HeardOnly(heard[a], r->offset_s));
        last = t, flight = f;
      }
    } else if (im.size() >= 3) {
      double next = end, flight = im[2].t_s - end;
      if (flight * c.lone_train_max_ratio / c.lone_train_min_ratio >= end - begin) continue;
      for (size_t a = heard.size(); a-- > 0;) {
        const double t = heard[a].t_s - r->offset_s;
        if ((*used)[a] || t >= next) continue;
        if (t <= begin + c.lone_train_min_ratio * flight) break;
        const double q = flight / (next - t);  // the restitution, roughly
        if (q > c.lone_train_max_ratio) continue;  // an echo or a stray sound
        if (q < c.lone_train_min_ratio) break;
        (*used)[a] = true;
        added.push_back(HeardOnly(heard[a], r->offset_s));
        flight = next - t, next = t;
      }
    }
  }
  im.insert(im.end(), added.begin(), added.end());
  std::stable_sort(im.begin(), im.end(),
                   [](const FusedImpact& a, const FusedImpact& b) { return a.t_s < b.t_s; });
}

// A flight is a bounce's only if it fits the train around it: no longer than train_growth
// times the one before, the one after no longer than train_growth times it. A longer one
// holds an impact nobody heard or saw (or a pickup between two drops): no height from it.
bool FitsTheTrain(const std::vector<FusedImpact>& im, size_t i, const ImpactFusionConfig& c) {
  const double flight = im[i + 1].t_s - im[i].t_s;
  if (i >= 1 && flight > c.train_growth * (im[i].t_s - im[i - 1].t_s)) return false;
  if (i + 2 < im.size() && im[i + 2].t_s - im[i + 1].t_s > c.train_growth * flight) return false;
  return true;
}

}  // namespace

const char* ImpactSourceName(ImpactSource s) {
  switch (s) {
    case ImpactSource::kAudio: return "audio";
    case ImpactSource::kVideo: return "video";
    case ImpactSource::kBoth: return "both";
  }
  return "?";
}

double FlightTimeHeight(double flight_s, double g, double k) {
  if (!(flight_s > 0) || !(g > 0)) return kNaN;
  if (k <= 0) return g * flight_s * flight_s / 8;
  // Flight time grows with the apex height: bisect.
  double lo = 0, hi = g * flight_s * flight_s / 4;
  while (RiseTime(hi, g, k) + FallTime(hi, g, k) < flight_s) hi *= 2;
  for (int i = 0; i < 100 && hi - lo > 1e-12; ++i) {
    const double mid = 0.5 * (lo + hi);
    (RiseTime(mid, g, k) + FallTime(mid, g, k) < flight_s ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

FusionResult FuseImpacts(const std::vector<AudioImpact>& heard_in, const std::vector<double>& seen,
                         double video_end_s, const ImpactFusionConfig& c) {
  FusionResult r;
  std::vector<AudioImpact> heard;
  for (const auto& a : heard_in)
    if (a.t_s >= -c.max_offset_s && a.t_s <= video_end_s + 1.0) heard.push_back(a);
  std::sort(heard.begin(), heard.end(), [](const auto& x, const auto& y) { return x.t_s < y.t_s; });
  r.heard = static_cast<int>(heard.size());
  // Echoes are the impacts they follow, heard again: paired with the picture they would move
  // the offset by their delay, and count as clicks it does not explain.
  const size_t before_echoes = heard.size();
  for (size_t a = heard.size(); a-- > 0;)
    for (size_t b = a; b-- > 0 && heard[a].t_s - heard[b].t_s < c.echo_s;)
      if (heard[b].strength >= c.echo_loudness * heard[a].strength) {
        heard.erase(heard.begin() + static_cast<long>(a));
        break;
      }
  const int echoes = static_cast<int>(before_echoes - heard.size());
  std::vector<double> ht;
  for (const auto& a : heard) ht.push_back(a.t_s);
  r.seen = static_cast<int>(seen.size());

  // The offset pairing the most impacts (ties: the smallest residuals). The offsets pairing a
  // set of impacts are those within the tolerance of every pair's difference: the most
  // pairs are found at a difference or at the tolerance's edge beside one (two clicks 31 ms
  // apart in their differences pair at one offset with a 20 ms tolerance, at neither
  // difference).
  std::vector<int> pair(seen.size(), -1);
  double best_residual = 0;
  const double edge = 0.999 * c.match_tolerance_s;
  for (double a : ht)
    for (double v : seen)
      for (const double d : {a - v, a - v - edge, a - v + edge}) {
        if (std::abs(d) > c.max_offset_s) continue;
        double residual = 0;
        const std::vector<int> p = Pair(ht, seen, d, c.match_tolerance_s, &residual);
        if (Count(p) > Count(pair) || (Count(p) == Count(pair) && Count(p) > 0 && residual < best_residual)) {
          pair = p;
          best_residual = residual;
          r.offset_s = d;
        }
      }
  if (Count(pair) > 0) {  // refine: the median of the pairs' differences
    std::vector<double> diffs;
    for (size_t v = 0; v < seen.size(); ++v)
      if (pair[v] >= 0) diffs.push_back(ht[pair[v]] - seen[v]);
    std::nth_element(diffs.begin(), diffs.begin() + diffs.size() / 2, diffs.end());
    r.offset_s = diffs[diffs.size() / 2];
    double residual = 0;
    const std::vector<int> refined = Pair(ht, seen, r.offset_s, c.match_tolerance_s, &residual);
    if (Count(refined) >= Count(pair)) pair = refined;
  }
  r.matched = Count(pair);
  int heard_in_span = 0;  // clicks heard while the picture saw impacts
  if (!seen.empty())
    for (double a : ht)
      if (a >= seen.front() + r.offset_s - c.match_tolerance_s &&
          a <= seen.back() + r.offset_s + c.match_tolerance_s)
        ++heard_in_span;
  const bool too_few_seen = static_cast<int>(seen.size()) < c.min_matches;
  r.sound_used = !too_few_seen && r.matched >= c.min_matches &&
                 r.matched >= c.min_match_fraction * heard_in_span;
  if (too_few_seen)
    r.verdict = std::to_string(seen.size()) +
                " impact(s) seen: too few to check the sound against the picture";
  else if (!r.sound_used)
    r.verdict = "the sound does not agree with the picture (" + std::to_string(r.matched) + " of " +
                std::to_string(seen.size()) + " seen impacts and of " +
                std::to_string(heard_in_span) + " clicks paired at any one offset), not used";
  else
    r.verdict = fmt::format("sound used: {} of {} seen impacts heard, sound lags the picture by {:.1f} ms", r.matched,
                            seen.size(), r.offset_s * 1e3);

  std::vector<bool> used(heard.size(), false);
  for (size_t v = 0; v < seen.size(); ++v) {
    FusedImpact f;
    f.video_t_s = seen[v];
    f.t_s = seen[v];
    f.audio_t_s = kNaN;
    if (r.sound_used && pair[v] >= 0) {
      const AudioImpact& a = heard[pair[v]];
      used[pair[v]] = true;
      f.source = ImpactSource::kBoth;
      f.t_s = a.t_s - r.offset_s;
      f.audio_t_s = a.t_s;
      f.strength = a.strength;
      f.confidence = a.confidence;
    }
    r.impacts.push_back(f);
  }

  if (r.sound_used) {
    MergeSeenIntoHeard(heard, &used, c, &r);
    FillGapsWithHeard(heard, &used, c, &r);
    if (!r.merged_seen.empty())
      r.verdict += "; " + std::to_string(r.merged_seen.size()) +
                   " seen impact(s) were a heard one seen twice, dropped";
  }

  // Heard only: the bounce train going on after the last impact both heard and seen,
  // flights shrinking; after the last one the picture saw, when it saw one more unheard (up to
  // there the picture watched the ball: a click between its impacts is no bounce, and the gaps
  // it missed one in are filled above).
  int last_both = -1, first_both = -1;
  for (size_t i = 0; i < r.impacts.size(); ++i)
    if (r.impacts[i].source == ImpactSource::kBoth) {
      last_both = static_cast<int>(i);
      if (first_both < 0) first_both = static_cast<int>(i);
    }
  if (r.sound_used && last_both >= 1) {
    const size_t last_seen = r.impacts.size() - 1;
    double last = r.impacts[last_seen].t_s;
    double flight = last - r.impacts[last_seen - 1].t_s;
    for (size_t a = 0; a < heard.size(); ++a) {
      const double t = heard[a].t_s - r.offset_s;
      if (used[a] || t <= last) continue;
      const double f = t - last;
      if (f < c.train_min_ratio * flight) continue;  // an echo or a stray sound
      if (f > c.train_growth * flight) break;        // the train has ended
      r.impacts.push_back(HeardOnly(heard[a], r.offset_s));
      used[a] = true;
      last = t, flight = f;
    }
  }
  // ... and before the first one: the bounces heard before the picture found the ball (the
  // tracker locks on late), going back in time with flights growing as a bounce train's
  // do: each flight's ratio to the one after it (the restitution, roughly) close to the
  // ratio of the two heard-and-seen flights after it. A seen impact the picture timed
  // poorly (beyond the pairing tolerance) within a quarter flight of such a heard impact is
  // that impact.
  // The two flights after it may end at impacts only heard (the picture missed them): with the
  // sound checked against the picture, heard times are the better ones.
  const auto heard_at = [&](int i) {
    return i < static_cast<int>(r.impacts.size()) && r.impacts[i].source != ImpactSource::kVideo;
  };
  if (r.sound_used && first_both >= 0 && heard_at(first_both + 1) && heard_at(first_both + 2)) {
    double next = r.impacts[first_both].t_s;
    double flight = r.impacts[first_both + 1].t_s - next;
    double ratio = (r.impacts[first_both + 2].t_s - r.impacts[first_both + 1].t_s) / flight;
    for (int a = static_cast<int>(heard.size()) - 1; a >= 0; --a) {
      const double t = heard[a].t_s - r.offset_s;
      if (used[a] || t >= next) continue;
      const double f = next - t;
      const double q = flight / f;
      if (q > c.lone_train_max_ratio + c.lone_train_ratio_step) continue;  // an echo, a stray sound
      if (q < c.lone_train_min_ratio || std::abs(q - ratio) > 2 * c.lone_train_ratio_step) break;
      used[a] = true;
      FusedImpact h = HeardOnly(heard[a], r.offset_s);
      for (FusedImpact& v : r.impacts)
        if (v.source == ImpactSource::kVideo && std::abs(v.video_t_s - h.t_s) <= 0.25 * f) {
          h.source = ImpactSource::kBoth;
          h.video_t_s = v.video_t_s;
          v.t_s = kNaN;  // replaced by h
        }
      r.impacts.push_back(h);
      next = t, flight = f, ratio = q;
    }
    std::erase_if(r.impacts, [](const FusedImpact& v) { return std::isnan(v.t_s); });
  }
  if (too_few_seen) {  // nothing to check against: a heard bounce train, or nothing
    r.offset_s = 0;
    const std::vector<int> train = LongestBounceTrain(ht, c);
    if (static_cast<int>(train.size()) >= c.lone_train_min_impacts) {
      r.heard_train_only = true;
      r.verdict += "; listing the heard bounce train of " + std::to_string(train.size()) + " impacts";
      for (int a : train) {
        r.impacts.push_back(HeardOnly(heard[a], 0));
        used[a] = true;
      }
    } else {
      r.verdict += "; no bounce train heard either";
    }
  }
  r.rejected_sounds = echoes + static_cast<int>(std::count(used.begin(), used.end(), false));
  std::stable_sort(r.impacts.begin(), r.impacts.end(),
                   [](const FusedImpact& a, const FusedImpact& b) { return a.t_s < b.t_s; });

  for (size_t i = 0; i + 1 < r.impacts.size(); ++i) {
    const FusedImpact& a = r.impacts[i];
    const FusedImpact& b = r.impacts[i + 1];
    if (a.source == ImpactSource::kVideo || b.source == ImpactSource::kVideo) continue;
    if (!FitsTheTrain(r.impacts, i, c)) continue;
    HeardFlight f;
    f.from = static_cast<int>(i);
    f.flight_s = b.t_s - a.t_s;
    f.height_m = FlightTimeHeight(f.flight_s, c.g_mps2, c.drag_per_m);
    f.apex_t_s = a.t_s + RiseTime(f.height_m, c.g_mps2, c.drag_per_m);
    f.heard_only = a.source == ImpactSource::kAudio || b.source == ImpactSource::kAudio;
    r.flights.push_back(f);
  }
  return r;
}

}  // namespace bouncefit
