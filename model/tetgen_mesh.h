#pragma once
// Tetrahedral meshes of a sphere made by the `tetgen` program, as in the paper: a geodesic
// sphere surface of a given resolution is written as a piecewise linear complex (.smesh),
// `tetgen -p -q<ratio> -a<maxvol>` fills it with tetrahedra, and its .node/.ele/.face output
// is read back.
//
// The sphere is meshed at unit radius (so the paper's max-volume bounds 0.01-0.1 keep their
// meaning for every ball size); the model scales it to the ball's radius. Meshes are cached
// by their parameters in memory (one per process, shared read-only) and on disk.
#include <array>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

namespace bouncefit {

struct TetMeshParams {
  // Geodesic frequency of the surface: every face of an icosahedron is split into
  // resolution^2 triangles, giving 10*resolution^2 + 2 surface vertices (1 -> 12, 3 -> 92,
  // 4 -> 162, 6 -> 362). tetgen may add Steiner points on the surface.
  int resolution = 3;
  double radius_edge_ratio = 1.5;  // tetgen -q: max radius/edge ratio of a tetrahedron
  double max_volume = 0.1;         // tetgen -a: max tetrahedron volume, unit sphere = 4.19

  // The parameters as they are meshed and cached: ratio and volume rounded to 3 significant
  // decimals (a fitter moving them continuously would otherwise mesh forever).
  TetMeshParams Canonical() const;
  // "f3_q1.500_a0.1000": the cache key and file stem.
  std::string Key() const;
  // Empty when valid, else a one-line reason.
  std::string Validate() const;
};

struct TetMesh {
  TetMeshParams params;
  std::vector<std::array<double, 3>> nodes;  // unit sphere, centred at the origin
  std::vector<std::array<int, 4>> tetras;    // node indices
  std::vector<std::array<int, 3>> faces;     // boundary triangles, wound outward
  // Volume enclosed by the faces (> 0 when wound outward), unit sphere ~ 4.19.
  double SurfaceVolume() const;
};

struct TetgenOptions {
  std::string tetgen_path;            // "" = the build's BOUNCEFIT_TETGEN
  std::filesystem::path cache_dir;    // "" = DefaultMeshCacheDir(); "-" = no disk cache
  double timeout_s = 60;              // tetgen is killed after this
};

// $BOUNCEFIT_CACHE_DIR, else $XDG_CACHE_HOME/bouncefit/tetgen, else ~/.cache/bouncefit/tetgen,
// else a directory under the system temp dir.
std::filesystem::path DefaultMeshCacheDir();

// The sphere surface handed to tetgen, unit radius, faces wound outward.
void GeodesicSphere(int resolution, std::vector<std::array<double, 3>>* vertices,
                    std::vector<std::array<int, 3>>* faces);

// The mesh for these parameters: from the in-memory cache, else the disk cache, else by
// running tetgen (fork/exec, with a timeout). Thread-safe; concurrent requests for the same
// parameters run tetgen once. Throws std::runtime_error with a one-line message when tetgen
// is missing, fails, times out or writes something unreadable.
std::shared_ptr<const TetMesh> GetTetMesh(const TetMeshParams& params,
                                          const TetgenOptions& options = {});

// Always runs tetgen (no cache); for tests and the cache itself.
TetMesh RunTetgen(const TetMeshParams& params, const TetgenOptions& options = {});

// Number of tetgen runs in this process (for tests of the cache).
int TetgenRunCount();

}  // namespace bouncefit
