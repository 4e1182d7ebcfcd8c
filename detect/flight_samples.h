#pragma once
// The drop's samples in flight, kept by an arc or not, and the closed arcs taking back those
// that lie on them under a new calibration. An arc is followed with the scale of the moment:
// a first fall's few smeared frames at 24 fps measured it 25% high, and the ends of every
// rebound after it, off that scale, were turned away or dropped; the arcs then kept their
// five tops, which hold their curvature least.
#include <cstddef>
#include <vector>

#include "detect/detector_scene.h"
#include "detect/flight_arcs.h"

namespace bouncefit {

class FlightSamples {
 public:
  explicit FlightSamples(const DetectorScene& scene);

  // A sample of the drop in flight, whatever becomes of it.
  void Saw(const DetectorSample& s);
  void Clear();
  void RescaleTime(double k);
  // Each arc closed by a fitted impact takes back the samples seen between its impacts that
  // lie on it under the current calibration, within the gate a sample is followed with.
  // True when an arc gained a sample.
  bool ReadmitInto(FlightArcs& arcs) const;

  const std::vector<DetectorSample>& seen() const { return seen_; }

 private:
  static constexpr size_t kKept = 4096;
  const DetectorScene& scene_;
  std::vector<DetectorSample> seen_;
};

}  // namespace bouncefit
