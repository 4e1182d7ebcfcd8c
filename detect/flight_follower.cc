// Following a drop in flight: each sample judged against the current arc, kept, turned
// away or taken for a lookalike; the samples turned away becoming an impact, the arc's own
// again, or the end of the drop.
#include "detect/flight_follower.h"
#include "detect/detector_stats.h"

#include <Eigen/Core>

#include <algorithm>
#include <cmath>

namespace bouncefit {

using detector_stats::ParabolaAt;

constexpr int kMissesEndArc = 6;  // samples in a row off an arc that end it

FlightFollower::FlightFollower(const FlightFollowerConfig& config, DetectorScene& scene,
                               DropHost& host)
    : config_(config),
      scene_(scene),
      host_(host),
      arcs_(config_, scene_),
      seen_(scene_),
      impacts_(config_, scene_, arcs_, host_),
      continuation_(scene_, arcs_) {}

void FlightFollower::Start(DetectorArc first) {
  arcs_.arcs().clear();
  arcs_.arcs().push_back(std::move(first));
  off_.Clear();
}

void FlightFollower::Reset() {
  arcs_.arcs().clear();
  seen_.Clear();
  off_.Reset();
}

void FlightFollower::RescaleTime(double k) {
  off_.RescaleTime(k);
  seen_.RescaleTime(k);
  arcs_.RescaleTime(k);
}

void FlightFollower::OnFlight(const DetectorSample& s, std::vector<DetectorEvent>& ev) {
  DetectorArc& cur = arcs_.arcs().back();
  double up, wp, vp;
  if (!arcs_.Predict(cur, s.t, &up, &wp, &vp)) {
    // The first frames of an arc with no scale yet to follow it by: take what moves on the
    // same vertical line (a stray detection elsewhere is dropped), down in the first fall, up
    // in the rebounds after a fall seen from its hold too short to measure gravity by (three
    // samples below the hold at least: a "fall" of one is no flight of the ball's).
    const DetectorSample& last = cur.samples.back();
    const double g = scene_.Gate();
    const DetectorArc& first = arcs_.arcs().front();
    const bool rising = !cur.release && first.held &&
                        first.samples.size() >= first.hold_samples + 3;
    const double on = rising ? Down(last) - Down(s) : Down(s) - Down(last);
    // A rebound slows as it rises: a step no longer than the one before it.
    double most = 20 * g;
    if (rising && cur.samples.size() >= 2)
      most = std::max(most, Down(cur.samples[cur.samples.size() - 2]) - Down(last) + 2 * g);
    if (std::abs(Floor(s) - Floor(last)) <= 2 * g && on >= -g && on <= most) cur.samples.push_back(s);
    return;
  }
  const double u = Down(s), w = Floor(s);
  const double gap_frames = std::max(1.0, (s.t - cur.samples.back().t) / scene_.frame_dt());
  const double gate = arcs_.FollowGate(cur, s.t, vp, gap_frames);
  const double ru = u - up, rw = w - wp;
  // Farther from the arc than any rebound could have carried the ball since its last sample
  // (twice its speed over the gap, four radii and ten gates), and where the last such
  // detection was: something standing still elsewhere while the tracker has lost the ball (a
  // lookalike where the ball was held). Not a sample, not a sign that the arc ended: the drop
  // waits as if the ball were unseen. A far detection that moves may be the ball on a path the
  // arc did not foresee (a release the hold hid): it is off the arc as before.
  // Across, the reach is the arc's own sideways speed and the noise: past the floor the fall's
  // extrapolated speed, and the gate with it, grow every frame and would soon reach anywhere (a
  // lookalike at the picture's edge while a thrown ball bounced unseen, six frames at 30 fps,
  // ended its drop).
  const double reach = 2 * std::abs(vp) * scene_.frame_dt() * gap_frames + 4 * s.r + 10 * gate;
  const double across_reach =
      2 * std::abs(arcs_.SidewaysSpeed(cur)) * scene_.frame_dt() * gap_frames + 4 * s.r + 10 * scene_.Gate();
  const bool far = std::hypot(ru, rw) > reach || std::abs(rw) > across_reach;
  if (off_.FarAgain(s, far, gate)) {
    scene_.set_last_seen_t(off_.LastT(cur.samples.back().t));
    host_.OnNoSample(s.t, s.utime, ev);
    return;
  }
  // Before the first calibration a fall from the hand is followed with a guess from its first
  // few samples, a few pixels below the hand, where a pixel of noise is much of the drop (a
  // smeared 24 fps fall is located to pixels): a sample beyond that guess, below or above it,
  // further down the same line is the fall going faster or slower than guessed, not the end of
  // it (above, it is no rebound: the ball is lower than at its last sample).
  // Only while the fall is young (followed as a fall from the hand, under 10 samples): a "fall"
  // the hand drew slowly for seconds before the ball dropped is no guess to outrun.
  const bool young_fall_off_guess = !scene_.calibrated() && cur.release && cur.held &&
                                    cur.samples.size() < cur.hold_samples + 10 &&
                                    std::abs(ru) > gate && std::abs(ru) < 0.5 * reach &&
                                    std::abs(rw) <= 2 * gate && Down(s) > Down(cur.samples.back());
  if ((std::abs(ru) <= gate || young_fall_off_guess) && std::abs(rw) <= 2 * gate) {
    TakeBack(cur, {s});
    host_.OnSampleKept(s, ev);
    return;
  }
  // Off the arc past its fitted apex, the apex not out yet: the scale the arc is followed with
  // may be what is off (a first fall's gravity from a few smeared frames, 12% high on a clip
  // of a ball dropped on a table). Emitting the apex refits the scale with this arc's samples;
  // then the sample is judged again.
  if (!rejudging_ && scene_.calibrated() && cur.fit_ok && !cur.apex_emitted && !cur.apex_held && arcs_.arcs().size() >= 2 &&
      host_.ApexDue(cur, s.t)) {
    const double scale_before = scene_.scale();
    const int sequence_before = host_.Sequence();
    host_.OnNoSample(s.t, s.utime, ev);
    if (!host_.InFlight() || host_.Sequence() != sequence_before) return;
    DetectorSample again = s;
    again.t *= scene_.scale() / scale_before;  // the clock may have been decided by that refit
    rejudging_ = true;
    OnFlight(again, ev);
    rejudging_ = false;
    return;
  }
  OnOffArc(s, ru, rw, vp, gate, u, ev);
}

void FlightFollower::OnOffArc(const DetectorSample& s, double ru, double rw, double v_down, double gate,
                              double u, std::vector<DetectorEvent>& ev) {
  DetectorArc& cur = arcs_.arcs().back();
  const bool falling = v_down > 0;
  // Along the floor a rebound keeps its course to within the gate and what its impact did to
  // its speed there (friction, spin, a wall: up to all of it) since the last sample: the ball
  // may have been unseen through the impact (a small ball smeared into a pale streak at
  // 25 fps, lost for 9 frames, rebounding at a third of its speed along the floor).
  double vw = 0;
  if (cur.fit_ok) {
    vw = cur.fit.vw;
  } else if (cur.samples.size() >= 2) {
    const DetectorSample& a = cur.samples[cur.samples.size() - 2];
    const DetectorSample& b = cur.samples.back();
    if (b.t > a.t) vw = (Floor(b) - Floor(a)) / (b.t - a.t);
  }
  const double along_gate = 2 * gate + std::abs(vw) * (s.t - cur.samples.back().t);
  const bool rising = ru < -gate && falling && std::abs(rw) <= along_gate;
  off_.TurnAway(s, rising);
  if (AdoptOffArcSamples(cur)) return;
  if (rising) {
    switch (impacts_.Judge(cur, off_.rising())) {
      case RisingVerdict::kWaiting: break;
      case RisingVerdict::kOnTheArc: TakeBack(cur, off_.rising()); return;
      case RisingVerdict::kImpact: ConfirmImpact(s, false, ev); return;
      case RisingVerdict::kImpactAfterHop: ConfirmImpact(s, true, ev); return;
    }
  }
  if (off_.misses() >= kMissesEndArc) OnArcMissed(s, u, ev);
}

void FlightFollower::OnArcMissed(const DetectorSample& s, double u, std::vector<DetectorEvent>& ev) {
  // Six frames in a row off the arc: it has ended (at rest, caught, rolling away).
  DetectorArc& cur = arcs_.arcs().back();
  const bool near_floor = scene_.calibrated() && scene_.calibration().calibration.has_floor &&
                          std::abs(u - scene_.calibration().calibration.floor_centre_px()) <=
                              3 * scene_.Gate();
  const std::vector<DetectorSample> recent = off_.InTimeOrder();
  Eigen::Vector3d fall;
  if (!near_floor && continuation_.YoungFallContinues(cur, recent, &fall)) {
    // The release arc's young model lost its own fall (a push, a smeared 24 fps fall):
    // the samples it turned away are that fall, not the end of the drop. An arc not seen
    // held keeps only its samples on that fall: the still ones it began with were the hand.
    if (!cur.held) {
      const double t_last = recent.back().t, g = scene_.StartGate();
      std::erase_if(cur.samples, [&](const DetectorSample& q) {
        return std::abs(Down(q) - ParabolaAt(fall, q.t - t_last)) > g;
      });
    }
    TakeBack(cur, recent);
    return;
  }
  if (!near_floor && continuation_.ArcContinues(cur, recent)) {
    // The arc went on in free flight; the drop's gravity, fitted mostly to another arc (a
    // first fall on a slow-motion ramp, a push), is what turned it away: refit it with them.
    cur.samples.insert(cur.samples.end(), recent.begin(), recent.end());
    off_.Clear();
    host_.Recalibrate(s.utime, ev);
    arcs_.Refit(cur);
    return;
  }
  host_.EndSequence(near_floor ? "rest" : "broken", ev);
  if (!near_floor)
    for (const auto& o : recent) host_.OnWaiting(o, ev);
}

bool FlightFollower::AdoptOffArcSamples(DetectorArc& cur) {
  DetectorArc rebound;
  if (!continuation_.YoungReboundContinues(cur, off_.InTimeOrder(), &rebound)) return false;
  cur = std::move(rebound);
  off_.Clear();
  return true;
}

void FlightFollower::ConfirmImpact(const DetectorSample& s, bool after_hop, std::vector<DetectorEvent>& ev) {
  std::vector<DetectorArc>& arcs = arcs_.arcs();
  if (after_hop) {
    // The hop's samples are dropped and its impact withdrawn: one impact, timed anew, joins
    // the arcs either side.
    host_.ForgetImpact(static_cast<int>(arcs.size() - 1) + host_.FirstBounce());
    arcs.pop_back();
  }
  if (impacts_.LastSampleStraddles(arcs.back())) arcs.back().samples.pop_back();
  DetectorArc next;
  next.samples = off_.rising();
  off_.Clear();
  arcs.push_back(next);
  host_.OnImpactConfirmed(s, ev);
}

void FlightFollower::TakeBack(DetectorArc& cur, const std::vector<DetectorSample>& samples) {
  cur.samples.insert(cur.samples.end(), samples.begin(), samples.end());
  off_.Clear();
  arcs_.Refit(cur);
}

}  // namespace bouncefit
