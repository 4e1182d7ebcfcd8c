#include "model/tetgen_mesh.h"

#include <fmt/format.h>
#include <fcntl.h>
#include <signal.h>
#include <spawn.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <future>
#include <map>
#include <mutex>
#include <sstream>
#include <stdexcept>
#include <thread>
#include <unordered_map>

#ifndef BOUNCEFIT_TETGEN
#define BOUNCEFIT_TETGEN "tetgen"
#endif

extern char** environ;

namespace bouncefit {
namespace {

namespace fs = std::filesystem;
using Vec3 = std::array<double, 3>;

std::atomic<int> g_tetgen_runs{0};

// Bump when the mesh written to the disk cache changes for the same parameters.
constexpr const char* kCacheFormat = "v1";

Vec3 Sub(const Vec3& a, const Vec3& b) { return {a[0] - b[0], a[1] - b[1], a[2] - b[2]}; }
Vec3 Cross(const Vec3& a, const Vec3& b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}
double Dot(const Vec3& a, const Vec3& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

// ---- tetgen's file formats -------------------------------------------------------------

// The non-blank, non-comment lines of a tetgen output file, as token vectors.
std::vector<std::vector<std::string>> ReadRecords(const fs::path& path) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error("cannot read " + path.string());
  std::vector<std::vector<std::string>> records;
  std::string line;
  while (std::getline(in, line)) {
    const auto hash = line.find('#');
    if (hash != std::string::npos) line.resize(hash);
    std::istringstream ss(line);
    std::vector<std::string> tokens;
    std::string tok;
    while (ss >> tok) tokens.push_back(tok);
    if (!tokens.empty()) records.push_back(std::move(tokens));
  }
  return records;
}

long ToLong(const std::string& s, const fs::path& path) {
  char* end = nullptr;
  errno = 0;
  const long v = std::strtol(s.c_str(), &end, 10);
  if (errno || end == s.c_str() || *end) throw std::runtime_error("bad integer '" + s + "' in " + path.string());
  return v;
}

double ToDouble(const std::string& s, const fs::path& path) {
  char* end = nullptr;
  errno = 0;
  const double v = std::strtod(s.c_str(), &end);
  if (errno || end == s.c_str() || *end || !std::isfinite(v))
    throw std::runtime_error("bad number '" + s + "' in " + path.string());
  return v;
}

// Reads <stem>.node/.ele/.face (tetgen's output format, any index base) into a mesh with
// 0-based indices and faces wound outward.
TetMesh ReadTetgenFiles(const fs::path& stem, const TetMeshParams& params) {
  TetMesh mesh;
  mesh.params = params;
  const fs::path node_path = fs::path(stem.string() + ".node");
  const fs::path ele_path = fs::path(stem.string() + ".ele");
  const fs::path face_path = fs::path(stem.string() + ".face");

  const auto nodes = ReadRecords(node_path);
  if (nodes.empty() || nodes[0].size() < 2 || ToLong(nodes[0][1], node_path) != 3)
    throw std::runtime_error("bad header in " + node_path.string());
  const long n_nodes = ToLong(nodes[0][0], node_path);
  if (n_nodes < 4 || static_cast<long>(nodes.size()) != n_nodes + 1)
    throw std::runtime_error("wrong node count in " + node_path.string());
  const long base = ToLong(nodes[1][0], node_path);
  if (base != 0 && base != 1) throw std::runtime_error("bad first index in " + node_path.string());
  mesh.nodes.resize(static_cast<size_t>(n_nodes));
  for (long i = 0; i < n_nodes; ++i) {
    const auto& r = nodes[static_cast<size_t>(i + 1)];
    if (r.size() < 4 || ToLong(r[0], node_path) != i + base)
      throw std::runtime_error("bad node record in " + node_path.string());
    for (int d = 0; d < 3; ++d) mesh.nodes[static_cast<size_t>(i)][d] = ToDouble(r[1 + d], node_path);
  }
  auto index = [&](const std::string& s, const fs::path& path) {
    const long v = ToLong(s, path) - base;
    if (v < 0 || v >= n_nodes) throw std::runtime_error("node index out of range in " + path.string());
    return static_cast<int>(v);
  };

  const auto eles = ReadRecords(ele_path);
  if (eles.empty() || eles[0].size() < 2 || ToLong(eles[0][1], ele_path) != 4)
    throw std::runtime_error("bad header in " + ele_path.string() + " (need 4-node tetrahedra)");
  const long n_tets = ToLong(eles[0][0], ele_path);
  if (n_tets < 1 || static_cast<long>(eles.size()) != n_tets + 1)
    throw std::runtime_error("wrong tetrahedron count in " + ele_path.string());
  for (long i = 0; i < n_tets; ++i) {
    const auto& r = eles[static_cast<size_t>(i + 1)];
    if (r.size() < 5) throw std::runtime_error("bad tetrahedron record in " + ele_path.string());
    mesh.tetras.push_back({index(r[1], ele_path), index(r[2], ele_path), index(r[3], ele_path),
                           index(r[4], ele_path)});
  }

  // Each boundary face belongs to one tetrahedron; wind it away from that tet's 4th node.
  auto key_of = [](int a, int b, int c) {
    std::array<int, 3> k{a, b, c};
    std::sort(k.begin(), k.end());
    return (static_cast<uint64_t>(k[0]) << 42) | (static_cast<uint64_t>(k[1]) << 21) |
           static_cast<uint64_t>(k[2]);
  };
  std::unordered_map<uint64_t, int> opposite;
  opposite.reserve(mesh.tetras.size() * 4);
  for (const auto& t : mesh.tetras)
    for (int skip = 0; skip < 4; ++skip) {
      int f[3], k = 0;
      for (int j = 0; j < 4; ++j)
        if (j != skip) f[k++] = t[j];
      opposite[key_of(f[0], f[1], f[2])] = t[skip];
    }

  const auto faces = ReadRecords(face_path);
  if (faces.empty()) throw std::runtime_error("bad header in " + face_path.string());
  const long n_faces = ToLong(faces[0][0], face_path);
  if (n_faces < 4 || static_cast<long>(faces.size()) != n_faces + 1)
    throw std::runtime_error("wrong face count in " + face_path.string());
  for (long i = 0; i < n_faces; ++i) {
    const auto& r = faces[static_cast<size_t>(i + 1)];
    if (r.size() < 4) throw std::runtime_error("bad face record in " + face_path.string());
    std::array<int, 3> f{index(r[1], face_path), index(r[2], face_path), index(r[3], face_path)};
    const auto it = opposite.find(key_of(f[0], f[1], f[2]));
    if (it == opposite.end())
      throw std::runtime_error("boundary face of no tetrahedron in " + face_path.string());
    const auto& a = mesh.nodes[static_cast<size_t>(f[0])];
    const Vec3 normal = Cross(Sub(mesh.nodes[static_cast<size_t>(f[1])], a),
                              Sub(mesh.nodes[static_cast<size_t>(f[2])], a));
    if (Dot(normal, Sub(mesh.nodes[static_cast<size_t>(it->second)], a)) > 0) std::swap(f[1], f[2]);
    mesh.faces.push_back(f);
  }
  if (!(mesh.SurfaceVolume() > 0))
    throw std::runtime_error("mesh in " + stem.string() + " encloses no volume");
  return mesh;
}

void WriteSmesh(const fs::path& path, int resolution) {
  std::vector<Vec3> vertices;
  std::vector<std::array<int, 3>> faces;
  GeodesicSphere(resolution, &vertices, &faces);
  std::ofstream out(path);
  out << "# geodesic unit sphere, frequency " << resolution << "\n";
  out << vertices.size() << " 3 0 0\n";
  for (size_t i = 0; i < vertices.size(); ++i) {
    out << fmt::format("{} {:.17g} {:.17g} {:.17g}\n", i, vertices[i][0], vertices[i][1], vertices[i][2]);
  }
  out << faces.size() << " 0\n";
  for (const auto& f : faces) out << "3 " << f[0] << ' ' << f[1] << ' ' << f[2] << '\n';
  out << "0\n0\n";
  if (!out.flush()) throw std::runtime_error("cannot write " + path.string());
}

// Last non-empty line of a file (tetgen's error message), "" if none.
std::string LastLine(const fs::path& path) {
  std::ifstream in(path);
  std::string line, last;
  while (std::getline(in, line))
    if (line.find_first_not_of(" \t\r") != std::string::npos) last = line;
  return last;
}

struct TempDir {
  fs::path path;
  TempDir() {
    std::string templ = (fs::temp_directory_path() / "bouncefit-tetgen-XXXXXX").string();
    if (!mkdtemp(templ.data())) throw std::runtime_error("cannot create a temporary directory");
    path = templ;
  }
  ~TempDir() {
    std::error_code ec;
    fs::remove_all(path, ec);
  }
};

// Runs argv with stdout+stderr into log_path; returns the exit status, throws on spawn
// failure or timeout (after killing the child).
int RunWithTimeout(const std::vector<std::string>& argv, const fs::path& log_path, double timeout_s) {
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, STDIN_FILENO, "/dev/null", O_RDONLY, 0);
  posix_spawn_file_actions_addopen(&actions, STDOUT_FILENO, log_path.c_str(),
                                   O_WRONLY | O_CREAT | O_TRUNC, 0644);
  posix_spawn_file_actions_adddup2(&actions, STDOUT_FILENO, STDERR_FILENO);
  std::vector<char*> args;
  for (const auto& a : argv) args.push_back(const_cast<char*>(a.c_str()));
  args.push_back(nullptr);
  pid_t pid = 0;
  const int rc = posix_spawn(&pid, args[0], &actions, nullptr, args.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  if (rc != 0)
    throw std::runtime_error("cannot run tetgen '" + argv[0] + "': " + std::strerror(rc));

  const auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout_s);
  auto nap = std::chrono::microseconds(500);
  int status = 0;
  for (;;) {
    const pid_t r = waitpid(pid, &status, WNOHANG);
    if (r == pid) break;
    if (r < 0 && errno != EINTR) throw std::runtime_error(std::string("waitpid: ") + std::strerror(errno));
    if (std::chrono::steady_clock::now() > deadline) {
      kill(pid, SIGKILL);
      while (waitpid(pid, &status, 0) < 0 && errno == EINTR) {
      }
      throw std::runtime_error(fmt::format("tetgen timed out after {:.0f} s", timeout_s));
    }
    std::this_thread::sleep_for(nap);
    nap = std::min(nap * 2, std::chrono::microseconds(20000));
  }
  if (WIFEXITED(status)) return WEXITSTATUS(status);
  if (WIFSIGNALED(status)) return 128 + WTERMSIG(status);
  return -1;
}

std::string TetgenPath(const TetgenOptions& options) {
  return options.tetgen_path.empty() ? std::string(BOUNCEFIT_TETGEN) : options.tetgen_path;
}

fs::path CacheDir(const TetgenOptions& options) {
  if (options.cache_dir == "-") return {};
  return (options.cache_dir.empty() ? DefaultMeshCacheDir() : options.cache_dir) / kCacheFormat;
}

// Copies a file to dst atomically (temp file + rename), so concurrent processes never see
// a partial file.
void AtomicCopy(const fs::path& src, const fs::path& dst) {
  const fs::path tmp = dst.string() + ".tmp" + std::to_string(getpid()) + "_" +
                       std::to_string(std::hash<std::thread::id>{}(std::this_thread::get_id()));
  fs::copy_file(src, tmp, fs::copy_options::overwrite_existing);
  fs::rename(tmp, dst);
}

std::shared_ptr<const TetMesh> LoadOrMake(const TetMeshParams& params, const TetgenOptions& options) {
  const fs::path dir = CacheDir(options);
  if (!dir.empty()) {
    const fs::path stem = dir / ("sphere_" + params.Key());
    std::error_code ec;
    if (fs::exists(stem.string() + ".face", ec)) {
      try {
        return std::make_shared<const TetMesh>(ReadTetgenFiles(stem, params));
      } catch (const std::exception&) {
        // A damaged cache entry: mesh again and overwrite it.
      }
    }
  }
  auto mesh = std::make_shared<const TetMesh>(RunTetgen(params, options));
  return mesh;
}

}  // namespace

TetMeshParams TetMeshParams::Canonical() const {
  TetMeshParams p = *this;
  p.radius_edge_ratio = std::round(radius_edge_ratio * 100) / 100;
  p.max_volume = std::round(max_volume * 10000) / 10000;
  return p;
}

std::string TetMeshParams::Key() const {
  const TetMeshParams p = Canonical();
  return fmt::format("f{}_q{:.2f}_a{:.4f}", p.resolution, p.radius_edge_ratio, p.max_volume);
}

std::string TetMeshParams::Validate() const {
  const TetMeshParams p = Canonical();
  if (p.resolution < 1 || p.resolution > 16)
    return "mesh resolution " + std::to_string(resolution) + " is outside 1..16";
  if (!(p.radius_edge_ratio >= 1.0 && p.radius_edge_ratio <= 10))
    return fmt::format("radius/edge ratio {:.3f} is outside 1..10", radius_edge_ratio);
  if (!(p.max_volume >= 0.001 && p.max_volume <= 4.2))
    return fmt::format("max tetrahedron volume {:.4f} is outside 0.001..4.2", max_volume);
  return {};
}

double TetMesh::SurfaceVolume() const {
  double v = 0;
  for (const auto& f : faces)
    v += Dot(nodes[static_cast<size_t>(f[0])],
             Cross(nodes[static_cast<size_t>(f[1])], nodes[static_cast<size_t>(f[2])]));
  return v / 6;
}

fs::path DefaultMeshCacheDir() {
  if (const char* d = std::getenv("BOUNCEFIT_CACHE_DIR"); d && *d) return fs::path(d) / "tetgen";
  if (const char* d = std::getenv("XDG_CACHE_HOME"); d && *d) return fs::path(d) / "bouncefit" / "tetgen";
  if (const char* d = std::getenv("HOME"); d && *d) return fs::path(d) / ".cache" / "bouncefit" / "tetgen";
  return fs::temp_directory_path() / ("bouncefit-cache-" + std::to_string(getuid())) / "tetgen";
}

void GeodesicSphere(int f, std::vector<Vec3>* vertices, std::vector<std::array<int, 3>>* faces) {
  if (f < 1) throw std::invalid_argument("geodesic frequency must be >= 1");
  const double t = (1 + std::sqrt(5.0)) / 2;
  const Vec3 ico[12] = {{-1, t, 0}, {1, t, 0}, {-1, -t, 0}, {1, -t, 0}, {0, -1, t}, {0, 1, t},
                        {0, -1, -t}, {0, 1, -t}, {t, 0, -1}, {t, 0, 1}, {-t, 0, -1}, {-t, 0, 1}};
  const int ico_faces[20][3] = {{0, 11, 5}, {0, 5, 1},  {0, 1, 7},   {0, 7, 10}, {0, 10, 11},
                                {1, 5, 9},  {5, 11, 4}, {11, 10, 2}, {10, 7, 6}, {7, 1, 8},
                                {3, 9, 4},  {3, 4, 2},  {3, 2, 6},   {3, 6, 8},  {3, 8, 9},
                                {4, 9, 5},  {2, 4, 11}, {6, 2, 10},  {8, 6, 7},  {9, 8, 1}};
  vertices->clear();
  faces->clear();
  // A point of the subdivision is identified exactly by its integer weights on the
  // icosahedron's vertices, sorted by vertex: points on shared edges dedupe exactly.
  std::map<std::vector<std::pair<int, int>>, int> index_of;
  auto point = [&](const int v[3], const int w[3]) {
    std::vector<std::pair<int, int>> key;
    for (int k = 0; k < 3; ++k)
      if (w[k] > 0) key.emplace_back(v[k], w[k]);
    std::sort(key.begin(), key.end());
    const auto it = index_of.find(key);
    if (it != index_of.end()) return it->second;
    Vec3 p{0, 0, 0};
    for (const auto& [vi, wi] : key)
      for (int d = 0; d < 3; ++d) p[d] += ico[vi][d] * wi;
    const double len = std::sqrt(Dot(p, p));
    for (double& c : p) c /= len;
    const int id = static_cast<int>(vertices->size());
    vertices->push_back(p);
    index_of.emplace(std::move(key), id);
    return id;
  };
  for (const auto& tri : ico_faces) {
    // Grid (i, j) on the face: weights (f-i-j, i, j) on (A, B, C).
    std::vector<std::vector<int>> grid(static_cast<size_t>(f + 1));
    for (int i = 0; i <= f; ++i)
      for (int j = 0; j <= f - i; ++j) {
        const int w[3] = {f - i - j, i, j};
        grid[static_cast<size_t>(i)].push_back(point(tri, w));
      }
    auto at = [&](int i, int j) { return grid[static_cast<size_t>(i)][static_cast<size_t>(j)]; };
    for (int i = 0; i < f; ++i)
      for (int j = 0; j < f - i; ++j) {
        faces->push_back({at(i, j), at(i + 1, j), at(i, j + 1)});
        if (i + j < f - 1) faces->push_back({at(i + 1, j), at(i + 1, j + 1), at(i, j + 1)});
      }
  }
  for (auto& tri : *faces) {  // outward winding
    const auto& a = (*vertices)[static_cast<size_t>(tri[0])];
    const Vec3 n = Cross(Sub((*vertices)[static_cast<size_t>(tri[1])], a),
                         Sub((*vertices)[static_cast<size_t>(tri[2])], a));
    if (Dot(n, a) < 0) std::swap(tri[1], tri[2]);
  }
}

TetMesh RunTetgen(const TetMeshParams& requested, const TetgenOptions& options) {
  const TetMeshParams params = requested.Canonical();
  if (const std::string err = params.Validate(); !err.empty()) throw std::invalid_argument(err);
  const std::string tetgen = TetgenPath(options);
  if (access(tetgen.c_str(), X_OK) != 0)
    throw std::runtime_error("tetgen not found at '" + tetgen + "' (install the tetgen package)");

  TempDir tmp;
  const fs::path input = tmp.path / "sphere.smesh";
  WriteSmesh(input, params.resolution);
  // -p: mesh the surface as given; -q: quality (radius/edge); -a: max volume; -z: number
  // from 0; -Q: quiet.
  const std::string switches = fmt::format("-pzQq{:.2f}a{:.4f}", params.radius_edge_ratio, params.max_volume);
  const fs::path log = tmp.path / "tetgen.log";
  ++g_tetgen_runs;
  const int status = RunWithTimeout({tetgen, switches, input.string()}, log, options.timeout_s);
  if (status != 0) {
    std::string why = LastLine(log);
    throw std::runtime_error("tetgen " + switches + " failed (exit " + std::to_string(status) + ")" +
                             (why.empty() ? std::string() : ": " + why));
  }
  const fs::path out_stem = tmp.path / "sphere.1";
  TetMesh mesh;
  try {
    mesh = ReadTetgenFiles(out_stem, params);
  } catch (const std::exception& e) {
    throw std::runtime_error(std::string("tetgen ") + switches + " wrote an unreadable mesh: " + e.what());
  }

  if (const fs::path dir = CacheDir(options); !dir.empty()) {
    // The disk cache is an optimisation: failing to write it is not an error.
    std::error_code ec;
    fs::create_directories(dir, ec);
    if (!ec) {
      try {
        const std::string stem = (dir / ("sphere_" + params.Key())).string();
        // .face last: its presence marks a complete entry.
        AtomicCopy(out_stem.string() + ".node", stem + ".node");
        AtomicCopy(out_stem.string() + ".ele", stem + ".ele");
        AtomicCopy(out_stem.string() + ".face", stem + ".face");
      } catch (const std::exception&) {
      }
    }
  }
  return mesh;
}

std::shared_ptr<const TetMesh> GetTetMesh(const TetMeshParams& requested, const TetgenOptions& options) {
  const TetMeshParams params = requested.Canonical();
  if (const std::string err = params.Validate(); !err.empty()) throw std::invalid_argument(err);
  using Future = std::shared_future<std::shared_ptr<const TetMesh>>;
  static std::mutex mutex;
  static std::map<std::string, Future> cache;
  const std::string key = TetgenPath(options) + "|" + CacheDir(options).string() + "|" + params.Key();

  std::promise<std::shared_ptr<const TetMesh>> promise;
  Future future;
  bool mine = false;
  {
    std::lock_guard lock(mutex);
    auto it = cache.find(key);
    if (it == cache.end()) {
      future = promise.get_future().share();
      cache.emplace(key, future);
      mine = true;
    } else {
      future = it->second;
    }
  }
  if (mine) {
    try {
      promise.set_value(LoadOrMake(params, options));
    } catch (...) {
      promise.set_exception(std::current_exception());
      std::lock_guard lock(mutex);
      cache.erase(key);  // let a later call try again
    }
  }
  return future.get();
}

int TetgenRunCount() { return g_tetgen_runs.load(); }

}  // namespace bouncefit
