#pragma once
// Plays a node of a .glb back as a viewer does, at its animation's keys: the mesh's base
// positions plus its morph targets by the keyed weights, turned by the keyed rotation and
// moved by the keyed translation. Read with tinygltf, independently of the writer.
#include <tiny_gltf.h>

#include <array>
#include <cstring>
#include <filesystem>
#include <stdexcept>
#include <string>
#include <vector>

namespace bouncefit::testing {

inline std::vector<float> AccessorFloats(const tinygltf::Model& m, int index) {
  const tinygltf::Accessor& a = m.accessors.at(size_t(index));
  if (a.componentType != TINYGLTF_COMPONENT_TYPE_FLOAT) throw std::runtime_error("not floats");
  const tinygltf::BufferView& v = m.bufferViews.at(size_t(a.bufferView));
  const int n = tinygltf::GetNumComponentsInType(uint32_t(a.type));
  std::vector<float> out(a.count * size_t(n));
  std::memcpy(out.data(), m.buffers.at(size_t(v.buffer)).data.data() + v.byteOffset + a.byteOffset,
              out.size() * sizeof(float));
  return out;
}

inline tinygltf::Model LoadGlb(const std::filesystem::path& path) {
  tinygltf::Model m;
  tinygltf::TinyGLTF loader;
  std::string err, warn;
  if (!loader.LoadBinaryFromFile(&m, &err, &warn, path.string()))
    throw std::runtime_error(path.string() + ": " + err);
  return m;
}

inline int NodeNamed(const tinygltf::Model& m, const std::string& name) {
  for (size_t i = 0; i < m.nodes.size(); ++i)
    if (m.nodes[i].name == name) return int(i);
  return -1;
}

struct Playback {
  std::vector<double> t_s;
  std::vector<std::vector<std::array<double, 3>>> vertices_m;  // [key][vertex], world
};

// The node's vertices at every key of the first animation's channels on it.
inline Playback PlayNode(const tinygltf::Model& m, int node_index) {
  const tinygltf::Node& node = m.nodes.at(size_t(node_index));
  const tinygltf::Primitive& prim = m.meshes.at(size_t(node.mesh)).primitives.at(0);
  const std::vector<float> base = AccessorFloats(m, prim.attributes.at("POSITION"));
  std::vector<std::vector<float>> targets;
  for (const auto& t : prim.targets) targets.push_back(AccessorFloats(m, t.at("POSITION")));
  std::vector<float> times, translation, rotation, weights;
  for (const auto& c : m.animations.at(0).channels) {
    if (c.target_node != node_index) continue;
    const auto& s = m.animations[0].samplers.at(size_t(c.sampler));
    times = AccessorFloats(m, s.input);
    if (c.target_path == "translation") translation = AccessorFloats(m, s.output);
    if (c.target_path == "rotation") rotation = AccessorFloats(m, s.output);
    if (c.target_path == "weights") weights = AccessorFloats(m, s.output);
  }
  Playback p;
  const size_t n = base.size() / 3;
  for (size_t k = 0; k < times.size(); ++k) {
    p.t_s.push_back(times[k]);
    double q[4] = {0, 0, 0, 1};
    if (!rotation.empty())
      for (int a = 0; a < 4; ++a) q[a] = rotation[4 * k + size_t(a)];
    std::vector<std::array<double, 3>> at_k(n);
    for (size_t i = 0; i < n; ++i) {
      double v[3];
      for (size_t a = 0; a < 3; ++a) {
        v[a] = base[3 * i + a];
        for (size_t j = 0; j < targets.size(); ++j) v[a] += weights[k * targets.size() + j] * targets[j][3 * i + a];
      }
      // v' = v + 2 w (u x v) + 2 u x (u x v), u = q's vector part.
      const double u[3] = {q[0], q[1], q[2]}, w = q[3];
      const double c1[3] = {u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]};
      const double c2[3] = {u[1] * c1[2] - u[2] * c1[1], u[2] * c1[0] - u[0] * c1[2], u[0] * c1[1] - u[1] * c1[0]};
      for (size_t a = 0; a < 3; ++a)
        at_k[i][a] = v[a] + 2 * w * c1[a] + 2 * c2[a] + translation[3 * k + a];
    }
    p.vertices_m.push_back(std::move(at_k));
  }
  return p;
}

}  // namespace bouncefit::testing
