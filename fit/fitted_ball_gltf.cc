#include "fit/fitted_ball_gltf.h"

#include <tiny_gltf.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <string>

namespace bouncefit {
namespace {

constexpr int kFloat = TINYGLTF_COMPONENT_TYPE_FLOAT;
constexpr int kArrayBuffer = TINYGLTF_TARGET_ARRAY_BUFFER;
constexpr int kElementArrayBuffer = TINYGLTF_TARGET_ELEMENT_ARRAY_BUFFER;

tinygltf::Value ToValue(const nlohmann::json& j) {
  switch (j.type()) {
    case nlohmann::json::value_t::boolean: return tinygltf::Value(j.get<bool>());
    case nlohmann::json::value_t::number_integer:
    case nlohmann::json::value_t::number_unsigned: return tinygltf::Value(j.get<int>());
    case nlohmann::json::value_t::number_float: {
      const double v = j.get<double>();
      return std::isfinite(v) ? tinygltf::Value(v) : tinygltf::Value();
    }
    case nlohmann::json::value_t::string: return tinygltf::Value(j.get<std::string>());
    case nlohmann::json::value_t::array: {
      tinygltf::Value::Array a;
      for (const auto& e : j) a.push_back(ToValue(e));
      return tinygltf::Value(std::move(a));
    }
    case nlohmann::json::value_t::object: {
      tinygltf::Value::Object o;
      for (const auto& [k, v] : j.items()) o[k] = ToValue(v);
      return tinygltf::Value(std::move(o));
    }
    default: return {};
  }
}

// One buffer, every block 4-byte aligned; each block its own view and accessor.
class Builder {
 public:
  tinygltf::Model model;

  Builder() { model.buffers.emplace_back(); }

  // `components` floats per element (1, 3 or 4); min and max are kept for every accessor
  // (the spec requires them for positions and animation inputs).
  int Floats(const std::vector<float>& data, int components, int target) {
    const size_t count = data.size() / size_t(components);
    tinygltf::Accessor acc;
    acc.bufferView = View(data.data(), data.size() * sizeof(float), target);
    acc.componentType = kFloat;
    acc.count = count;
    acc.type = components == 1 ? TINYGLTF_TYPE_SCALAR
                               : components == 3 ? TINYGLTF_TYPE_VEC3 : TINYGLTF_TYPE_VEC4;
    acc.minValues.assign(size_t(components), 1e300);
    acc.maxValues.assign(size_t(components), -1e300);
    for (size_t i = 0; i < data.size(); ++i) {
      const size_t c = i % size_t(components);
      acc.minValues[c] = std::min(acc.minValues[c], double(data[i]));
      acc.maxValues[c] = std::max(acc.maxValues[c], double(data[i]));
    }
    model.accessors.push_back(acc);
    return int(model.accessors.size() - 1);
  }
  int Vec3s(const std::vector<std::array<float, 3>>& v, int target) {
    std::vector<float> flat;
    for (const auto& p : v) flat.insert(flat.end(), p.begin(), p.end());
    return Floats(flat, 3, target);
  }
  int Indices(const std::vector<std::array<int, 3>>& triangles) {
    std::vector<uint16_t> flat;
    for (const auto& t : triangles)
      for (int k : t) flat.push_back(uint16_t(k));
    tinygltf::Accessor acc;
    acc.bufferView = View(flat.data(), flat.size() * sizeof(uint16_t), kElementArrayBuffer);
    acc.componentType = TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT;
    acc.count = flat.size();
    acc.type = TINYGLTF_TYPE_SCALAR;
    model.accessors.push_back(acc);
    return int(model.accessors.size() - 1);
  }
  int Material(const std::string& name, std::array<double, 4> rgba, double roughness) {
    tinygltf::Material m;
    m.name = name;
    m.pbrMetallicRoughness.baseColorFactor.assign(rgba.begin(), rgba.end());
    m.pbrMetallicRoughness.metallicFactor = 0;
    m.pbrMetallicRoughness.roughnessFactor = roughness;
    if (rgba[3] < 1) m.alphaMode = "BLEND";
    model.materials.push_back(m);
    return int(model.materials.size() - 1);
  }

 private:
  int View(const void* data, size_t bytes, int target) {
    auto& buf = model.buffers[0].data;
    tinygltf::BufferView view;
    view.buffer = 0;
    view.byteOffset = buf.size();
    view.byteLength = bytes;
    view.target = target;
    const auto* p = static_cast<const unsigned char*>(data);
    buf.insert(buf.end(), p, p + bytes);
    buf.resize((buf.size() + 3) / 4 * 4, 0);
    model.bufferViews.push_back(view);
    return int(model.bufferViews.size() - 1);
  }
};

// The ball's mesh (with its morph targets) and its node; returns the node's index.
int AddBall(Builder* b, const std::string& name, const BallAnimation& a, int material) {
  tinygltf::Primitive prim;
  prim.mode = TINYGLTF_MODE_TRIANGLES;
  prim.material = material;
  prim.attributes["POSITION"] = b->Vec3s(a.base_m, kArrayBuffer);
  prim.attributes["NORMAL"] = b->Vec3s(a.normals, kArrayBuffer);
  prim.indices = b->Indices(a.triangles);
  tinygltf::Mesh mesh;
  mesh.name = name;
  tinygltf::Value::Array target_names;
  for (size_t j = 0; j < a.targets_m.size(); ++j) {
    prim.targets.push_back({{"POSITION", b->Vec3s(a.targets_m[j], kArrayBuffer)}});
    target_names.emplace_back("deformation_" + std::to_string(j + 1));
  }
  mesh.primitives.push_back(prim);
  if (!a.targets_m.empty()) {
    mesh.weights.assign(a.rest_weights.begin(), a.rest_weights.end());
    tinygltf::Value::Object extras;
    extras["targetNames"] = tinygltf::Value(std::move(target_names));  // names importers show
    mesh.extras = tinygltf::Value(std::move(extras));
  }
  b->model.meshes.push_back(mesh);
  tinygltf::Node node;
  node.name = name;
  node.mesh = int(b->model.meshes.size() - 1);
  node.translation.assign(a.translation_m[0].begin(), a.translation_m[0].end());
  if (!a.rotation.empty()) node.rotation.assign(a.rotation[0].begin(), a.rotation[0].end());
  b->model.nodes.push_back(node);
  return int(b->model.nodes.size() - 1);
}

// Keys the node's translation, rotation and weights on `anim`.
void AddChannels(Builder* b, int node, const BallAnimation& a, tinygltf::Animation* anim) {
  const std::vector<float> times(a.t_s.begin(), a.t_s.end());
  const int input = b->Floats(times, 1, 0);
  auto channel = [&](int output, const std::string& path) {
    tinygltf::AnimationSampler s;
    s.input = input;
    s.output = output;
    s.interpolation = "LINEAR";
    anim->samplers.push_back(s);
    tinygltf::AnimationChannel c;
    c.sampler = int(anim->samplers.size() - 1);
    c.target_node = node;
    c.target_path = path;
    anim->channels.push_back(c);
  };
  channel(b->Vec3s(a.translation_m, 0), "translation");
  if (!a.rotation.empty()) {
    std::vector<float> q;
    for (const auto& r : a.rotation) q.insert(q.end(), r.begin(), r.end());
    channel(b->Floats(q, 4, 0), "rotation");
  }
  if (!a.targets_m.empty()) {
    std::vector<float> w;
    for (const auto& k : a.weights) w.insert(w.end(), k.begin(), k.end());
    channel(b->Floats(w, 1, 0), "weights");
  }
}

// The floor: a square at y = 0, facing up.
int AddFloor(Builder* b, double half_m, int material) {
  BallAnimation quad;
  const float h = float(half_m);
  quad.base_m = {{-h, 0, -h}, {h, 0, -h}, {h, 0, h}, {-h, 0, h}};
  quad.normals.assign(4, {0, 1, 0});
  quad.triangles = {{0, 2, 1}, {0, 3, 2}};
  quad.translation_m = {{0, 0, 0}};
  return AddBall(b, "floor", quad, material);
}

// The tracked ball's centres (its samples with finite values, times increasing), beside the
// fitted ball.
BallAnimation RecordedAnimation(const RecordedTrack& track, const BallPreset& ball) {
  const double r = ball.radius_m();
  std::vector<double> t;
  std::vector<std::array<float, 3>> centres;
  const bool has_x = !track.horizontal_m.empty();
  if (track.bottom_height_m.size() != track.t_s.size() ||
      (has_x && track.horizontal_m.size() != track.t_s.size()))
    throw std::invalid_argument("recorded track: times, heights and positions differ in length");
  double x0 = NAN;
  for (size_t i = 0; i < track.t_s.size(); ++i) {
    const double x = has_x ? track.horizontal_m[i] : 0;
    if (!std::isfinite(track.t_s[i]) || !std::isfinite(track.bottom_height_m[i]) || !std::isfinite(x)) continue;
    if (!t.empty() && !(track.t_s[i] > t.back())) continue;
    if (std::isnan(x0)) x0 = x;
    t.push_back(track.t_s[i]);
    centres.push_back({float(RecordedBallOffsetM(ball) + x - x0), float(track.bottom_height_m[i] + r), 0});
  }
  if (t.empty()) throw std::invalid_argument("recorded track: no sample with a time and a height");
  return AnimateRigidSphere(t, centres, r);
}

}  // namespace

double RecordedBallOffsetM(const BallPreset& ball) { return 3 * ball.diameter_m; }

FittedBallGltf WriteFittedBallGltf(const std::filesystem::path& path, const BallModel& model,
                                   const BallPreset& ball, const CoefficientValues& values,
                                   double drop_height_m, const nlohmann::json& extras,
                                   const RecordedTrack* recorded,
                                   const FittedBallGltfOptions& options) {
  if (!(options.rate_hz > 0)) throw std::invalid_argument("glTF key rate must be > 0 per second");
  SimulationOptions drop;
  drop.drop_height_m = drop_height_m;
  // A ball with restitution e needs ~ sqrt(2H/g)(1 + 2/(1-e)) s; 20 s covers e < 0.95 from 2 m.
  drop.duration_s = options.duration_s > 0 ? options.duration_s : 6 + 10 * std::sqrt(drop_height_m);
  drop.min_bounce_height_m = options.min_bounce_height_m;
  drop.record_trajectory = true;
  drop.trajectory_rate_hz = options.rate_hz;
  drop.record_surface = true;
  FittedBallGltf out;
  out.path = path;
  out.simulation = model.Simulate(values, drop);
  const SimulationResult& sim = out.simulation;
  if (!sim.ok) throw std::runtime_error("the fitted ball diverges dropped from " +
                                        std::to_string(drop_height_m) + " m (" + sim.failure + ")");
  std::vector<double> t;
  for (const auto& s : sim.trajectory) t.push_back(s.t_s);
  BallAnimation fitted;
  if (!sim.surface.positions_m.empty()) {
    fitted = AnimateSurface(t, sim.surface, options.animation);
  } else {  // a model without a surface (the point mass): a rigid sphere on its centre
    std::vector<std::array<float, 3>> centres;
    for (const auto& s : sim.trajectory) centres.push_back({0, float(s.center_height_m), 0});
    fitted = AnimateRigidSphere(t, centres, ball.radius_m());
  }

  Builder b;
  b.model.asset.version = "2.0";
  b.model.asset.generator = "bouncefit";
  tinygltf::Animation anim;
  anim.name = "bounce";
  const int fitted_node = AddBall(&b, "fitted_ball", fitted, b.Material("fitted_ball", {0.95, 0.42, 0.08, 1}, 0.5));
  AddChannels(&b, fitted_node, fitted, &anim);
  std::vector<int> scene_nodes{fitted_node};
  double half = std::max(0.5, 0.6 * drop_height_m);
  if (recorded) {
    const BallAnimation rec = RecordedAnimation(*recorded, ball);
    const int node = AddBall(&b, "recorded_ball", rec, b.Material("recorded_ball", {0.15, 0.45, 0.95, 0.6}, 0.5));
    AddChannels(&b, node, rec, &anim);
    scene_nodes.push_back(node);
    for (const auto& c : rec.translation_m) half = std::max(half, std::abs(double(c[0])) + 5 * ball.radius_m());
  }
  scene_nodes.push_back(AddFloor(&b, half, b.Material("floor", {0.78, 0.78, 0.76, 1}, 0.9)));
  b.model.animations.push_back(anim);
  tinygltf::Scene scene;
  scene.name = "drop";
  scene.nodes = scene_nodes;
  b.model.scenes.push_back(scene);
  b.model.defaultScene = 0;

  out.keys = fitted.t_s.size();
  out.vertices = fitted.base_m.size();
  out.morph_targets = fitted.targets_m.size();
  out.rotation = !fitted.rotation.empty();
  out.max_error_m = fitted.max_error_m;
  out.max_deformation_m = fitted.max_deformation_m;
  nlohmann::json all = extras.is_object() ? extras : nlohmann::json::object();
  all["units"] = {{"length", "m"}, {"time", "real s since the start apex (the ball at rest at drop_height_m)"}, {"up", "+y"}};
  all["animation"] = {{"model", model.name()},
                      {"drop_height_m", drop_height_m},
                      {"key_rate_hz", options.rate_hz},
                      {"keys", out.keys},
                      {"morph_targets", out.morph_targets},
                      {"max_vertex_error_m", out.max_error_m},
                      {"max_deformation_m", out.max_deformation_m},
                      {"simulated_bounce_heights_m", sim.bounce_heights_m},
                      {"simulated_apex_times_s", sim.apex_times_s},
                      {"simulated_impact_times_s", sim.impact_times_s}};
  if (recorded) all["animation"]["recorded_ball_offset_x_m"] = RecordedBallOffsetM(ball);
  b.model.asset.extras = ToValue(all);

  std::ostringstream glb;
  tinygltf::TinyGLTF writer;
  if (!writer.WriteGltfSceneToStream(&b.model, glb, false, true))
    throw std::runtime_error("cannot serialise " + path.string());
  const std::string bytes = glb.str();
  if (!path.parent_path().empty()) std::filesystem::create_directories(path.parent_path());
  std::ofstream file(path, std::ios::binary);
  file.write(bytes.data(), std::streamsize(bytes.size()));
  if (!file) throw std::runtime_error("cannot write " + path.string());
  out.bytes = bytes.size();
  return out;
}

}  // namespace bouncefit
