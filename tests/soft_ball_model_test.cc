// The Bullet soft-body ball (model/soft_ball_model.h) and its TetGen meshes
// (model/tetgen_mesh.h), with real tetgen runs and real Bullet simulations.
#include <gtest/gtest.h>

#include <sys/stat.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <set>
#include <thread>

#include <nlohmann/json.hpp>

#include "model/ball_preset.h"
#include "model/coefficient_table.h"
#include "model/soft_ball_model.h"
#include "model/tetgen_mesh.h"
#include "tests/test_support.h"

namespace bouncefit {
namespace {

constexpr double kPi = 3.14159265358979323846;

TetgenOptions ScratchCache(const std::string& name) {
  TetgenOptions o;
  o.cache_dir = testing::ScratchDir(name);
  return o;
}

bool OneLine(const std::string& s) { return !s.empty() && s.find('\n') == std::string::npos; }

TEST(GeodesicSphere, CountsUnitLengthAndOutwardFaces) {
  for (int f = 1; f <= 6; ++f) {
    std::vector<std::array<double, 3>> v;
    std::vector<std::array<int, 3>> faces;
    GeodesicSphere(f, &v, &faces);
    EXPECT_EQ(v.size(), size_t(10 * f * f + 2)) << f;
    EXPECT_EQ(faces.size(), size_t(20 * f * f)) << f;
    for (const auto& p : v) EXPECT_NEAR(p[0] * p[0] + p[1] * p[1] + p[2] * p[2], 1.0, 1e-12);
    TetMesh m;
    m.nodes = v;
    m.faces = faces;
    EXPECT_GT(m.SurfaceVolume(), 0.6 * 4.0 / 3.0 * kPi) << f;
    EXPECT_LT(m.SurfaceVolume(), 4.0 / 3.0 * kPi) << f;
  }
}

TEST(TetgenMesh, MeshesTheUnitSphereWithOutwardBoundaryFaces) {
  TetMeshParams p;  // the model's default mesh
  const TetMesh m = RunTetgen(p, ScratchCache("tetgen_default"));
  EXPECT_GE(m.nodes.size(), 92u);  // the 92 surface vertices of frequency 3, and more
  EXPECT_LT(m.nodes.size(), 400u);
  EXPECT_GT(m.tetras.size(), 0u);
  EXPECT_GE(m.faces.size(), 180u);
  const double v = m.SurfaceVolume();
  EXPECT_GT(v, 0.9 * 4.0 / 3.0 * kPi);
  EXPECT_LT(v, 4.0 / 3.0 * kPi);
  // Tetrahedra fill the same volume.
  double tets = 0;
  for (const auto& t : m.tetras) {
    const auto& a = m.nodes[size_t(t[0])];
    double e[3][3];
    for (int k = 0; k < 3; ++k)
      for (int d = 0; d < 3; ++d) e[k][d] = m.nodes[size_t(t[size_t(k + 1)])][d] - a[d];
    tets += std::abs(e[0][0] * (e[1][1] * e[2][2] - e[1][2] * e[2][1]) -
                     e[0][1] * (e[1][0] * e[2][2] - e[1][2] * e[2][0]) +
                     e[0][2] * (e[1][0] * e[2][1] - e[1][1] * e[2][0])) / 6;
  }
  EXPECT_NEAR(tets, v, 1e-9 * v);
  for (const auto& f : m.faces)
    for (int i : f) EXPECT_TRUE(i >= 0 && size_t(i) < m.nodes.size());
}

TEST(TetgenMesh, ParametersChangeTheMesh) {
  const TetgenOptions o = ScratchCache("tetgen_params");
  TetMeshParams coarse, fine;
  fine.resolution = 5;
  const auto a = GetTetMesh(coarse, o), b = GetTetMesh(fine, o);
  EXPECT_GT(b->faces.size(), a->faces.size());
  TetMeshParams small = coarse;
  small.max_volume = 0.02;
  EXPECT_GT(GetTetMesh(small, o)->tetras.size(), a->tetras.size());
}

TEST(TetgenMesh, CachedInMemoryAndOnDisk) {
  TetgenOptions o = ScratchCache("tetgen_cache");
  TetMeshParams p;
  p.resolution = 4;
  p.radius_edge_ratio = 1.8;
  const int runs0 = TetgenRunCount();
  const auto a = GetTetMesh(p, o);
  EXPECT_EQ(TetgenRunCount(), runs0 + 1);
  // Same parameters (up to the rounding of the key): the same shared mesh, no new run.
  TetMeshParams q = p;
  q.radius_edge_ratio = 1.8001;
  EXPECT_EQ(GetTetMesh(q, o).get(), a.get());
  EXPECT_EQ(TetgenRunCount(), runs0 + 1);
  // On disk under the cache dir; another process (here: another in-memory key for the same
  // cache dir) loads it without running tetgen.
  bool found = false;
  for (const auto& e : std::filesystem::recursive_directory_iterator(o.cache_dir))
    found |= e.path().filename() == "sphere_" + p.Key() + ".face";
  EXPECT_TRUE(found);
  TetgenOptions other = o;
  other.tetgen_path = std::string(BOUNCEFIT_TETGEN);  // same program, different key text
  other.timeout_s = 59;
  other.cache_dir = o.cache_dir / ".";
  const auto b = GetTetMesh(p, other);
  EXPECT_NE(b.get(), a.get());
  EXPECT_EQ(TetgenRunCount(), runs0 + 1);
  EXPECT_EQ(b->nodes, a->nodes);
  EXPECT_EQ(b->tetras, a->tetras);
  EXPECT_EQ(b->faces, a->faces);
}

TEST(TetgenMesh, MissingFailingOrHangingTetgenIsAOneLineError) {
  TetMeshParams p;
  p.resolution = 2;
  TetgenOptions o = ScratchCache("tetgen_errors");
  o.tetgen_path = "/nonexistent/tetgen";
  try {
    RunTetgen(p, o);
    FAIL() << "no error";
  } catch (const std::runtime_error& e) {
    EXPECT_TRUE(OneLine(e.what())) << e.what();
    EXPECT_NE(std::string(e.what()).find("tetgen not found"), std::string::npos) << e.what();
  }
  o.tetgen_path = "/bin/false";
  try {
    RunTetgen(p, o);
    FAIL() << "no error";
  } catch (const std::runtime_error& e) {
    EXPECT_TRUE(OneLine(e.what())) << e.what();
    EXPECT_NE(std::string(e.what()).find("failed (exit 1)"), std::string::npos) << e.what();
  }
  const auto script = o.cache_dir / "hang.sh";
  std::ofstream(script) << "#!/bin/sh\nsleep 30\n";
  std::filesystem::permissions(script, std::filesystem::perms::owner_all);
  o.tetgen_path = script.string();
  o.timeout_s = 0.3;
  const auto t0 = std::chrono::steady_clock::now();
  try {
    RunTetgen(p, o);
    FAIL() << "no error";
  } catch (const std::runtime_error& e) {
    EXPECT_TRUE(OneLine(e.what())) << e.what();
    EXPECT_NE(std::string(e.what()).find("timed out"), std::string::npos) << e.what();
  }
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(), 5.0);
  // Through the model: a failed evaluation, not an exception.
  SoftBallModelConfig cfg;
  cfg.tetgen.tetgen_path = "/nonexistent/tetgen";
  cfg.tetgen.cache_dir = "-";
  const SoftBallModel model(*FindBallPreset("pingpong"), cfg);
  const SimulationResult r = model.Simulate({{"mesh_resolution", 5}}, {});
  EXPECT_FALSE(r.ok);
  EXPECT_TRUE(OneLine(r.failure)) << r.failure;
  EXPECT_NE(r.failure.find("tetgen not found"), std::string::npos) << r.failure;
}

TEST(MeasureBounces, ParabolaApexesFromCameraSamples) {
  // Two arcs between impacts at t = 0, 0.4, 0.72 s, sampled at 120 Hz.
  const double g = 9.81;
  std::vector<double> t, y;
  const double impacts[] = {0.0, 0.4, 0.72};
  for (int k = -20; k < 120; ++k) {
    const double tk = k / 120.0;
    double h = 0;
    if (tk < 0) h = 0.5 * g * tk * tk;
    for (int i = 0; i < 2; ++i)
      if (tk >= impacts[i] && tk < impacts[i + 1]) {
        const double d = impacts[i + 1] - impacts[i], s = tk - impacts[i];
        h = 0.5 * g * s * (d - s);
      }
    t.push_back(tk);
    y.push_back(h);
  }
  const MeasuredBounces m = MeasureBounces(t, y, 6);
  ASSERT_EQ(m.apex_heights_m.size(), 2u);
  EXPECT_NEAR(m.apex_heights_m[0], g * 0.4 * 0.4 / 8, 1e-9);
  EXPECT_NEAR(m.apex_heights_m[1], g * 0.32 * 0.32 / 8, 1e-9);
  EXPECT_NEAR(m.apex_times_s[0], 0.2, 1e-9);
  EXPECT_NEAR(m.apex_times_s[1], 0.56, 1e-9);
}

SimulationOptions Drop(double h, double duration = 3) {
  SimulationOptions o;
  o.drop_height_m = h;
  o.duration_s = duration;
  return o;
}

TEST(SoftBallModel, CoefficientsHaveNamesBoundsAndDefaultsInside) {
  const SoftBallModel model(*FindBallPreset("wiffle"));
  const auto specs = model.Coefficients();
  std::set<std::string> names;
  for (const auto& s : specs) {
    names.insert(s.name);
    EXPECT_LE(s.lower, s.default_value) << s.name;
    EXPECT_LE(s.default_value, s.upper) << s.name;
    EXPECT_FALSE(s.description.empty()) << s.name;
  }
  for (const char* n : {"linear_stiffness", "angular_stiffness", "volume_stiffness", "pressure",
                        "damping", "drag", "lift", "soft_rigid_impulse_split",
                        "soft_kinetic_impulse_split", "soft_soft_impulse_split", "mesh_resolution",
                        "radius_edge_ratio", "max_volume", "volume_conservation",
                        "contact_hardness", "floor_friction", "floor_restitution", "rebound_boost"})
    EXPECT_TRUE(names.count(n)) << n;
  EXPECT_EQ(names.size(), specs.size());  // no duplicates
}

TEST(SoftBallModel, BadInputsAreFailedEvaluations) {
  const SoftBallModel model(*FindBallPreset("pingpong"));
  SimulationResult r = model.Simulate({{"no_such_coefficient", 1}}, Drop(1));
  EXPECT_FALSE(r.ok);
  EXPECT_NE(r.failure.find("unknown coefficient"), std::string::npos) << r.failure;
  r = model.Simulate({{"linear_stiffness", 2}}, Drop(1));
  EXPECT_FALSE(r.ok);
  EXPECT_NE(r.failure.find("outside"), std::string::npos) << r.failure;
  r = model.Simulate({}, Drop(-1));
  EXPECT_FALSE(r.ok);
}

TEST(SoftBallModel, FacesAppendedSoPressureAndVolumeWork) {
  const SoftBallModel model(*FindBallPreset("airball"));
  const auto mesh = model.Mesh({});
  EXPECT_FALSE(mesh->faces.empty());
  EXPECT_GT(mesh->SurfaceVolume(), 0);
  // Without faces Bullet's volume is 0 and kPR gives NaN (docs/MODEL.md); with them, a pressurised
  // ball with volume conservation bounces.
  const SimulationResult r =
      model.Simulate({{"pressure", 2}, {"volume_conservation", 50}}, Drop(0.5, 2));
  ASSERT_TRUE(r.ok) << r.failure;
  EXPECT_FALSE(r.bounce_heights_m.empty());
}

TEST(SoftBallModel, BouncesAndComesToRestOnTheFloor) {
  for (const char* name : {"pingpong", "softball"}) {
    const BallPreset ball = *FindBallPreset(name);
    const SoftBallModel model(ball);
    SimulationOptions o = Drop(1.0, 4);
    o.record_trajectory = true;
    o.min_bounce_height_m = -1;  // no early stop: watch it lie on the floor
    const SimulationResult r = model.Simulate({}, o);
    ASSERT_TRUE(r.ok) << name << ": " << r.failure;
    ASSERT_FALSE(r.bounce_heights_m.empty()) << name;
    EXPECT_GT(r.bounce_heights_m[0], 0.02) << name;
    EXPECT_LT(r.bounce_heights_m[0], 1.0) << name;
    ASSERT_FALSE(r.impact_times_s.empty());
    // Free fall from 1 m (bottom): first impact after ~0.45 s.
    EXPECT_NEAR(r.impact_times_s[0], std::sqrt(2 / 9.81), 0.02) << name;
    ASSERT_GT(r.trajectory.size(), 400u);
    EXPECT_NEAR(r.trajectory.front().bottom_height_m, 1.0, 0.002);
    // At rest: the ball lies on the floor, its centre about one radius up (not 25 cm).
    const TrajectorySample& last = r.trajectory.back();
    EXPECT_NEAR(last.t_s, 4.0, 0.01);
    EXPECT_NEAR(last.center_height_m, ball.radius_m(), 0.15 * ball.radius_m()) << name;
    EXPECT_NEAR(last.bottom_height_m, 0, 0.1 * ball.radius_m()) << name;
    EXPECT_NEAR(last.width_height_ratio, 1, 0.2) << name;
  }
}

TEST(SoftBallModel, EarlyStopOnceBouncesAreTooLow) {
  const SoftBallModel model(*FindBallPreset("softball"));
  SimulationOptions o = Drop(1.0, 6);
  o.min_bounce_height_m = 0.05;
  const SimulationResult r = model.Simulate({}, o);
  ASSERT_TRUE(r.ok) << r.failure;
  for (double h : r.bounce_heights_m) EXPECT_GE(h, 0.05);
  EXPECT_LT(r.wall_time_s, 2.0);
}

// A fit asks for the bounces it recorded only (it costs less): the run ends at the impact
// after bounce k, with bounces 1..k bit for bit those of the full run, in less simulated time
// (simulated, not wall time: wall time of a 0.05 s run is noise on a loaded CI machine).
TEST(SoftBallModel, StopsOnceTheBouncesAskedForAreMeasured) {
  const SoftBallModel model(*FindBallPreset("pingpong"));
  SimulationOptions o = Drop(1.0, 6);
  o.min_bounce_height_m = 0.005;
  const CoefficientValues table = SoftBallPresetTable("pingpong")->values;
  const SimulationResult full = model.Simulate(table, o);
  ASSERT_TRUE(full.ok) << full.failure;
  ASSERT_GE(full.bounce_heights_m.size(), 5u);
  o.max_bounces = 3;
  const SimulationResult cut = model.Simulate(table, o);
  ASSERT_TRUE(cut.ok) << cut.failure;
  ASSERT_EQ(cut.bounce_heights_m.size(), 3u);
  for (size_t i = 0; i < 3; ++i) EXPECT_EQ(cut.bounce_heights_m[i], full.bounce_heights_m[i]);
  EXPECT_LT(cut.simulated_time_s, 0.8 * full.simulated_time_s);
}

TEST(SoftBallModel, DeterministicToTheLastBitAcrossRunsAndThreads) {
  const SoftBallModel model(*FindBallPreset("wiffle"));
  const CoefficientValues v = {{"rebound_boost", 0.3}, {"pressure", 1}};
  SimulationOptions o = Drop(0.8, 2.5);
  o.record_trajectory = true;
  o.min_bounce_height_m = 0.002;
  const SimulationResult a = model.Simulate(v, o);
  ASSERT_TRUE(a.ok) << a.failure;
  ASSERT_GE(a.bounce_heights_m.size(), 2u);
  std::vector<SimulationResult> parallel(4);
  std::vector<std::thread> threads;
  for (auto& r : parallel) threads.emplace_back([&] { r = model.Simulate(v, o); });
  for (auto& t : threads) t.join();
  for (const auto& b : parallel) {
    ASSERT_TRUE(b.ok);
    EXPECT_EQ(b.bounce_heights_m, a.bounce_heights_m);  // exact, not near
    EXPECT_EQ(b.apex_times_s, a.apex_times_s);
    ASSERT_EQ(b.trajectory.size(), a.trajectory.size());
    for (size_t i = 0; i < a.trajectory.size(); ++i) {
      EXPECT_EQ(b.trajectory[i].center_height_m, a.trajectory[i].center_height_m);
      EXPECT_EQ(b.trajectory[i].width_height_ratio, a.trajectory[i].width_height_ratio);
    }
  }
  // A different model object, same settings: same bits.
  const SoftBallModel again(*FindBallPreset("wiffle"));
  EXPECT_EQ(again.Simulate(v, o).bounce_heights_m, a.bounce_heights_m);
}

TEST(SoftBallModel, DivergenceIsReportedEarlyNotACrash) {
  const SoftBallModel model(*FindBallPreset("pingpong"));
  // Huge volume conservation: the contact response explodes.
  SimulationResult r = model.Simulate({{"volume_conservation", 1000}, {"pressure", 0}}, Drop(1, 6));
  EXPECT_FALSE(r.ok);
  EXPECT_NE(r.failure.find("diverged"), std::string::npos) << r.failure;
  EXPECT_TRUE(OneLine(r.failure));
  EXPECT_LT(r.wall_time_s, 2.0);
  // Artificial boost on top of a bouncy ball: more energy out than in.
  r = model.Simulate({{"rebound_boost", 1}, {"drag", 0}}, Drop(1, 6));
  EXPECT_FALSE(r.ok);
  EXPECT_NE(r.failure.find("energy growth"), std::string::npos) << r.failure;
  // A wall-time cap stops anything.
  SoftBallModelConfig cfg;
  cfg.max_wall_time_s = 1e-6;
  const SoftBallModel capped(*FindBallPreset("pingpong"), cfg);
  r = capped.Simulate({}, Drop(1, 6));
  EXPECT_FALSE(r.ok);
  EXPECT_NE(r.failure.find("wall-time limit"), std::string::npos) << r.failure;
}

TEST(SoftBallModel, ReboundBoostRaisesTheBounceSmoothly) {
  const SoftBallModel model(*FindBallPreset("airball"));
  double previous = 0;
  for (double boost : {0.0, 0.1, 0.2, 0.3}) {
    const SimulationResult r = model.Simulate({{"rebound_boost", boost}}, Drop(1, 2));
    ASSERT_TRUE(r.ok) << r.failure;
    ASSERT_FALSE(r.bounce_heights_m.empty());
    EXPECT_GT(r.bounce_heights_m[0], previous) << boost;
    previous = r.bounce_heights_m[0];
  }
}

// rebound_boost_per_mps: restitution that falls with impact speed. The boost is unchanged at
// the reference speed (a 1 m drop) and smaller for a faster impact.
TEST(SoftBallModel, ReboundBoostFallsWithImpactSpeed) {
  const SoftBallModel model(*FindBallPreset("airball"));
  auto first = [&](double drop, double slope) {
    const SimulationResult r =
        model.Simulate({{"rebound_boost", 0.3}, {"rebound_boost_per_mps", slope}}, Drop(drop, 2.0));
    EXPECT_TRUE(r.ok) << r.failure;
    return r.bounce_heights_m.empty() ? 0.0 : r.bounce_heights_m[0] / drop;
  };
  const double at2 = first(2.0, 0), at2_sloped = first(2.0, 0.1);
  EXPECT_LT(at2_sloped, at2 - 0.03) << "from 2 m: " << at2 << " -> " << at2_sloped;
  // From 0.3 m (slower than the reference) the boost grows instead.
  EXPECT_GT(first(0.3, 0.1), first(0.3, 0) + 0.01);
}

// The stored coefficient tables (model/presets/) are complete and hold for this model's time
// step and iterations (the slow test re-simulates them against the presets' heights).
TEST(SoftBallPresets, TablesNameKnownCoefficientsForThisModel) {
  for (const char* name : {"pingpong", "wiffle", "softball", "airball"}) {
    const auto path = std::filesystem::path(BOUNCEFIT_SOURCE_DIR) / "model" / "presets" /
                      (std::string("soft_ball_") + name + ".json");
    std::ifstream in(path);
    ASSERT_TRUE(in) << path;
    const auto j = nlohmann::json::parse(in);
    const SoftBallModel model(*FindBallPreset(name));
    EXPECT_EQ(j.at("ball"), name);
    EXPECT_EQ(j.at("time_step_s").get<double>(), model.config().time_step_s);
    EXPECT_EQ(j.at("position_iterations").get<int>(), model.config().position_iterations);
    CoefficientValues v;
    for (const auto& [k, x] : j.at("coefficients").items()) v[k] = x.get<double>();
    std::string error;
    model.Complete(v, &error);
    EXPECT_EQ(error, "") << name;
    EXPECT_EQ(v.size(), model.Coefficients().size()) << name;
  }
}

TEST(SimulateCommand, ListsCoefficientsAndPrintsHeights) {
  std::string out;
  ASSERT_EQ(testing::RunCommand(testing::BouncefitExe() + " simulate --list-coeffs", &out), 0) << out;
  for (const char* n : {"linear_stiffness", "rebound_boost", "contact_hardness", "mesh_resolution"})
    EXPECT_NE(out.find(n), std::string::npos) << n;
  ASSERT_EQ(testing::RunCommand(testing::BouncefitExe() +
                                    " simulate --ball wiffle --drop 0.6 --coeffs "
                                    "rebound_boost=0.2,drag=0.6 --json --duration 2",
                                &out),
            0)
      << out;
  const auto j = nlohmann::json::parse(out);
  EXPECT_EQ(j.at("ball"), "wiffle");
  EXPECT_EQ(j.at("coefficients").at("rebound_boost").get<double>(), 0.2);
  EXPECT_FALSE(j.at("bounce_heights_m").empty());
  EXPECT_FALSE(j.at("trajectory").empty());
  // The same through the library: the CLI prints the model's numbers.
  const SoftBallModel model(*FindBallPreset("wiffle"));
  SimulationOptions o = Drop(0.6, 2);
  const auto r = model.Simulate({{"rebound_boost", 0.2}, {"drag", 0.6}}, o);
  EXPECT_EQ(j.at("bounce_heights_m").get<std::vector<double>>(), r.bounce_heights_m);

  ASSERT_EQ(testing::RunCommand(testing::BouncefitExe() +
                                    " simulate --ball softball --coeffs preset --csv --no-trajectory",
                                &out),
            0)
      << out;
  EXPECT_EQ(out.rfind("bounce,apex_t_s,height_m\n", 0), 0u) << out;
}

TEST(SimulateCommand, ErrorsAreOneLine) {
  for (const char* args : {"--coeffs no_such=1", "--coeffs linear_stiffness=7",
                           "--coeffs /nonexistent.json", "--ball nosuchball",
                           "--coeffs volume_conservation=1000,pressure=0", "--csv --json"}) {
    std::string out;
    const int rc = testing::RunCommand(testing::BouncefitExe() + " simulate " + args, &out);
    EXPECT_TRUE(rc == 1 || rc == 2) << args << ": exit " << rc;  // an error, or a bad flag
    EXPECT_EQ(std::count(out.begin(), out.end(), '\n'), 1) << args << ": " << out;
    EXPECT_EQ(out.rfind("bouncefit simulate: error: ", 0), 0u) << out;
  }
}

// A fit's file names its ball: simulate runs that ball (an airball's coefficients on a
// ping-pong ball gave heights 6% off the fit's), and says so when --ball names another.
TEST(SimulateCommand, TakesTheBallTheCoefficientFileNames) {
  const std::filesystem::path file = testing::ScratchDir("simulate_ball") / "airball.json";
  std::ofstream(file) << R"({"model": "bullet-softbody", "ball": "airball",
      "values": {"rebound_restitution": 0.8, "rebound_restitution_per_mps": 0.02}})";
  std::string from_file, given, other;
  ASSERT_EQ(testing::RunCommand(testing::BouncefitExe() + " simulate --no-trajectory --coeffs " +
                                    file.string(), &from_file), 0) << from_file;
  ASSERT_EQ(testing::RunCommand(testing::BouncefitExe() + " simulate --no-trajectory --ball airball --coeffs " +
                                    file.string(), &given), 0) << given;
  auto heights = [](const std::string& out) { return out.substr(out.find("bounce heights")); };
  EXPECT_EQ(heights(from_file), heights(given));  // (the first line says the wall time)
  EXPECT_NE(from_file.find("airball (0.15 m"), std::string::npos) << from_file;
  EXPECT_EQ(testing::RunCommand(testing::BouncefitExe() + " simulate --ball pingpong --coeffs " +
                                    file.string(), &other), 2);  // a flag the file contradicts
  EXPECT_NE(other.find("for the airball ball, not pingpong"), std::string::npos) << other;
}

}  // namespace
}  // namespace bouncefit
