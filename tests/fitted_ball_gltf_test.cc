// The fitted ball's glTF: read back with tinygltf and played at its keys, the surface is the
// simulated one (within 1 mm at every key) and its lowest point rises to the simulation's
// apexes; the recorded ball and the extras are there.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>

#include "fit/fit_export.h"
#include "fit/fitted_ball_gltf.h"
#include "model/ball_preset.h"
#include "model/coefficient_table.h"
#include "model/point_mass_model.h"
#include "model/soft_ball_model.h"
#include "tests/gltf_playback.h"
#include "tests/test_support.h"

namespace bouncefit {
namespace {

// The built-in sample's final fit (README: the restitution law of the ping-pong ball).
FitUpdate SampleFit(double drop_height_m) {
  const SoftBallModel model(*FindBallPreset("pingpong"));
  FitUpdate u;
  u.model = "bullet-softbody";
  u.method = "restitution-curve";
  u.final = true;
  std::string error;
  u.values = model.Complete({{"rebound_restitution", 0.9198},
                             {"rebound_restitution_per_mps", 0.004889},
                             {"drag", 0.4945}},
                            &error);
  u.drop_height_m = drop_height_m;
  u.time_step_s = model.config().time_step_s;
  u.iterations = model.config().position_iterations;
  u.recorded_m = {0.652, 0.46};
  u.simulated_m = {0.6521, 0.4597};
  u.residual_m = 0.00054;
  return u;
}

// The drop the .glb animates, run again here: same model, values and options.
SimulationResult Simulate(const BallModel& model, const CoefficientValues& values, double drop_m,
                          double min_bounce_m = FittedBallGltfOptions{}.min_bounce_height_m) {
  SimulationOptions o;
  o.drop_height_m = drop_m;
  o.duration_s = 6 + 10 * std::sqrt(drop_m);
  o.min_bounce_height_m = min_bounce_m;
  o.record_trajectory = true;
  o.record_surface = true;
  return model.Simulate(values, o);
}

double Lowest(const std::vector<std::array<double, 3>>& v) {
  double y = 1e9;
  for (const auto& p : v) y = std::min(y, p[1]);
  return y;
}

// Every bounce of 2 cm or more: the played ball's lowest point at its highest near the
// simulated apex, against the simulation's own lowest point there (what simulated.csv
// holds; only the playback differs) and against its apex (the centre's parabola less the
// radius: the turned polyhedron's lowest point differs from it too).
void ExpectApexes(const testing::Playback& p, const SimulationResult& sim, const char* what) {
  int checked = 0;
  double worst_surface = 0, worst_apex = 0;
  for (size_t b = 0; b < sim.bounce_heights_m.size(); ++b) {
    if (sim.bounce_heights_m[b] < 0.02) continue;
    double played = -1, simulated = -1;
    for (size_t k = 0; k < p.t_s.size(); ++k)
      if (std::abs(p.t_s[k] - sim.apex_times_s[b]) < 0.05) {
        played = std::max(played, Lowest(p.vertices_m[k]));
        simulated = std::max(simulated, sim.trajectory[k].bottom_height_m);
      }
    EXPECT_NEAR(played, simulated, FittedBallGltfOptions{}.animation.tolerance_m + 1e-6)
        << what << " bounce " << b + 1;
    EXPECT_NEAR(played, sim.bounce_heights_m[b], 1e-3) << what << " bounce " << b + 1;
    worst_surface = std::max(worst_surface, std::abs(played - simulated));
    worst_apex = std::max(worst_apex, std::abs(played - sim.bounce_heights_m[b]));
    ++checked;
  }
  EXPECT_GE(checked, 5) << what;
  std::printf("%s: %d bounces >= 2 cm, the played ball's highest lowest point vs the simulated "
              "mesh's: worst %.3f mm; vs the simulated apex: worst %.3f mm\n",
              what, checked, worst_surface * 1000, worst_apex * 1000);
}

TEST(FittedBallGltf, WriteFitExportsWritesTheBallThatPlaysAsSimulated) {
  const BallPreset ball = *FindBallPreset("pingpong");
  const FitUpdate u = SampleFit(0.5);
  const auto dir = testing::ScratchDir("export");
  const auto written = WriteFitExports(dir, u, ball, {"sample.avi", "run", nullptr});
  const auto glb = dir / "fitted_ball.glb";
  ASSERT_NE(std::find(written.begin(), written.end(), glb), written.end());
  const tinygltf::Model m = testing::LoadGlb(glb);
  std::printf("fitted_ball.glb: %ju bytes\n", std::uintmax_t(std::filesystem::file_size(glb)));
  EXPECT_LT(std::filesystem::file_size(glb), 400u * 1024);

  const int node = testing::NodeNamed(m, "fitted_ball");
  ASSERT_GE(node, 0);
  ASSERT_GE(testing::NodeNamed(m, "floor"), 0);
  EXPECT_EQ(testing::NodeNamed(m, "recorded_ball"), -1);
  const testing::Playback p = testing::PlayNode(m, node);
  ASSERT_GT(p.t_s.size(), 100u);
  EXPECT_NEAR(p.t_s[1] - p.t_s[0], 1.0 / 120, 1e-6);  // keyed at 120 per second
  EXPECT_EQ(p.t_s[0], 0);

  const SoftBallModel model(ball);
  // The export ends the animation at the ball's chatter hops.
  const SimulationResult sim = Simulate(model, u.values, 0.5, ball.chatter_hop_m());
  ASSERT_TRUE(sim.ok) << sim.failure;
  ASSERT_EQ(sim.surface.positions_m.size(), p.t_s.size());
  double worst = 0;
  for (size_t k = 0; k < p.t_s.size(); ++k)
    for (size_t i = 0; i < p.vertices_m[k].size(); ++i)
      for (size_t a = 0; a < 3; ++a)
        worst = std::max(worst, std::abs(p.vertices_m[k][i][a] - sim.surface.positions_m[k][i][a]));
  EXPECT_LT(worst, 1e-3);
  std::printf("played surface vs simulated: worst coordinate %.4f mm over %zu keys x %zu vertices\n",
              worst * 1000, p.t_s.size(), p.vertices_m[0].size());
  ExpectApexes(p, sim, "sample fit from 0.5 m");

  // The asset's extras: the ball, the law, drag, residual, the clip.
  const tinygltf::Value& x = m.asset.extras;
  EXPECT_EQ(x.Get("ball").Get("preset").Get<std::string>(), "pingpong");
  EXPECT_NEAR(x.Get("ball").Get("diameter_m").GetNumberAsDouble(), 0.04, 1e-12);
  EXPECT_NEAR(x.Get("restitution_law").Get("e0").GetNumberAsDouble(), 0.9198, 1e-12);
  EXPECT_NEAR(x.Get("drag_coefficient").GetNumberAsDouble(), 0.4945, 1e-12);
  EXPECT_NEAR(x.Get("fit").Get("residual_m").GetNumberAsDouble(), 0.00054, 1e-12);
  EXPECT_EQ(x.Get("fit").Get("clip").Get<std::string>(), "sample.avi");
}

TEST(FittedBallGltf, BulletsOwnContactDeformsTheBallAndMorphTargetsPlayIt) {
  // The stored ping-pong set rebounds on Bullet's own contact (plus the boost): the ball
  // squashes, and the squash must play.
  const BallPreset ball = *FindBallPreset("pingpong");
  const auto table = SoftBallPresetTable("pingpong");
  ASSERT_TRUE(table.has_value());
  SoftBallModelConfig config;
  config.time_step_s = *table->time_step_s;
  const SoftBallModel model(ball, config);
  const auto path = testing::ScratchDir("preset") / "ball.glb";
  const FittedBallGltf w = WriteFittedBallGltf(path, model, ball, table->values, 0.4, {});
  std::printf("preset from 0.4 m: %zu bytes, %zu keys, %zu vertices, %zu morph targets, rotation %d, "
              "deformation up to %.3f mm, played within %.3f mm\n",
              w.bytes, w.keys, w.vertices, w.morph_targets, int(w.rotation),
              w.max_deformation_m * 1000, w.max_error_m * 1000);
  EXPECT_LE(w.max_error_m, FittedBallGltfOptions{}.animation.tolerance_m + 1e-9);
  const tinygltf::Model m = testing::LoadGlb(path);
  const testing::Playback p = testing::PlayNode(m, testing::NodeNamed(m, "fitted_ball"));
  const SimulationResult sim = Simulate(model, table->values, 0.4);
  ASSERT_TRUE(sim.ok) << sim.failure;
  ASSERT_EQ(sim.surface.positions_m.size(), p.t_s.size());
  double worst = 0;
  for (size_t k = 0; k < p.t_s.size(); ++k)
    for (size_t i = 0; i < p.vertices_m[k].size(); ++i)
      for (size_t a = 0; a < 3; ++a)
        worst = std::max(worst, std::abs(p.vertices_m[k][i][a] - sim.surface.positions_m[k][i][a]));
  EXPECT_LT(worst, 1e-3);
  ExpectApexes(p, sim, "preset from 0.4 m");
}

TEST(FittedBallGltf, ARecordedTrackBecomesTheRecordedBallOnTheSameClock) {
  // A recorded track: the point mass's drop, as a tracker would give it (bottom heights),
  // drifting sideways.
  const BallPreset ball = *FindBallPreset("tennis");
  const PointMassModel truth(ball);
  SimulationOptions o;
  o.drop_height_m = 0.6;
  o.duration_s = 2;
  o.record_trajectory = true;
  const SimulationResult drop = truth.Simulate({{"restitution", 0.8}}, o);
  ASSERT_TRUE(drop.ok) << drop.failure;
  RecordedTrack track;
  for (const auto& s : drop.trajectory) {
    track.t_s.push_back(s.t_s);
    track.bottom_height_m.push_back(s.bottom_height_m);
    track.horizontal_m.push_back(0.1 + 0.05 * s.t_s);
  }
  track.t_s.push_back(track.t_s.back());  // a repeated time: skipped
  track.bottom_height_m.push_back(0);
  track.horizontal_m.push_back(0);
  FitUpdate u;
  u.model = "point-mass";
  u.values = {{"restitution", 0.8}, {"restitution_per_mps", 0}, {"drag_coefficient", 0.5}};
  u.drop_height_m = 0.6;
  const auto path = testing::ScratchDir("recorded") / "ball.glb";
  WriteFitGltf(path, u, ball, 0.6, {"", "fit", &track});
  const tinygltf::Model m = testing::LoadGlb(path);
  const int rec = testing::NodeNamed(m, "recorded_ball");
  ASSERT_GE(rec, 0);
  const testing::Playback p = testing::PlayNode(m, rec);
  ASSERT_EQ(p.t_s.size(), drop.trajectory.size());
  for (size_t k = 0; k < p.t_s.size(); k += 17) {
    EXPECT_NEAR(p.t_s[k], drop.trajectory[k].t_s, 1e-6);
    EXPECT_NEAR(Lowest(p.vertices_m[k]), drop.trajectory[k].bottom_height_m, 0.1e-3) << k;
    double x = 0;
    for (const auto& v : p.vertices_m[k]) x += v[0] / double(p.vertices_m[k].size());
    EXPECT_NEAR(x, RecordedBallOffsetM(ball) + 0.05 * p.t_s[k], 1e-5) << k;
  }
  // The point mass's fitted ball: a rigid sphere on its centre.
  const testing::Playback f = testing::PlayNode(m, testing::NodeNamed(m, "fitted_ball"));
  EXPECT_NEAR(Lowest(f.vertices_m[0]), 0.6, 1e-5);
  EXPECT_NEAR(m.asset.extras.Get("restitution_law").Get("e0").GetNumberAsDouble(), 0.8, 1e-12);
}

TEST(BallAnimation, TheRigidSphereIsClosedAndWoundOutward) {
  const BallAnimation a = AnimateRigidSphere({0}, {{0, 0, 0}}, 1.0, 3);
  EXPECT_EQ(a.base_m.size(), 10u * 9 + 2);
  EXPECT_EQ(a.triangles.size(), 20u * 9);
  double volume = 0;  // positive only when every face is wound outward
  for (const auto& t : a.triangles) {
    const auto& p = a.base_m[size_t(t[0])];
    const auto& q = a.base_m[size_t(t[1])];
    const auto& s = a.base_m[size_t(t[2])];
    volume += (p[0] * (q[1] * s[2] - q[2] * s[1]) - p[1] * (q[0] * s[2] - q[2] * s[0]) +
               p[2] * (q[0] * s[1] - q[1] * s[0])) / 6;
  }
  EXPECT_GT(volume, 0.9 * 4.0 / 3 * M_PI);  // the polyhedron is inside its sphere
  EXPECT_LT(volume, 4.0 / 3 * M_PI);
}

}  // namespace
}  // namespace bouncefit
