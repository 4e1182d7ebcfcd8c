#include "fit/ball_animation.h"

#include <Eigen/Core>
#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <Eigen/SVD>

#include <algorithm>
#include <cmath>
#include <map>
#include <stdexcept>
#include <tuple>

namespace bouncefit {
namespace {

using Vec3 = Eigen::Vector3d;

Vec3 V(const std::array<float, 3>& p) { return {p[0], p[1], p[2]}; }
std::array<float, 3> F(const Vec3& v) { return {float(v.x()), float(v.y()), float(v.z())}; }

// Area-weighted vertex normals of a closed mesh.
std::vector<std::array<float, 3>> Normals(const std::vector<std::array<float, 3>>& x,
                                          const std::vector<std::array<int, 3>>& triangles) {
  std::vector<Vec3> n(x.size(), Vec3::Zero());
  for (const auto& t : triangles) {
    const Vec3 a = V(x[size_t(t[0])]), b = V(x[size_t(t[1])]), c = V(x[size_t(t[2])]);
    const Vec3 face = (b - a).cross(c - a);
    for (int k : t) n[size_t(k)] += face;
  }
  std::vector<std::array<float, 3>> out(x.size());
  for (size_t i = 0; i < x.size(); ++i)
    out[i] = F(n[i].norm() > 0 ? Vec3(n[i].normalized()) : Vec3(0, 1, 0));
  return out;
}

Vec3 Centroid(const std::vector<std::array<float, 3>>& x) {
  Vec3 c = Vec3::Zero();
  for (const auto& p : x) c += V(p);
  return c / double(x.size());
}

// The rotation taking the rest offsets onto the current ones best (least squares, Kabsch).
Eigen::Matrix3d BestRotation(const Eigen::MatrixXd& rest, const Eigen::MatrixXd& now) {
  const Eigen::Matrix3d h = rest.transpose() * now;
  Eigen::JacobiSVD<Eigen::Matrix3d> svd(h, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d d = Eigen::Matrix3d::Identity();
  d(2, 2) = (svd.matrixV() * svd.matrixU().transpose()).determinant() < 0 ? -1 : 1;
  return svd.matrixV() * d * svd.matrixU().transpose();
}

// d ~ u diag(s) v^T over its `count` largest components, from the eigenvectors of the smaller
// of its Gram matrices (d d^T or d^T d). A dense SVD of d gives the same, but its template
// (BDCSVD) is most of this unit's build time; the few components that matter are well apart,
// and the caller measures what they leave on d itself. Components of no weight are left out.
struct Components {
  Eigen::MatrixXd u, v;
  Eigen::VectorXd s;
};
Components PrincipalComponents(const Eigen::MatrixXd& d, Eigen::Index count) {
  const bool over_rows = d.rows() <= d.cols();
  const Eigen::MatrixXd gram = over_rows ? Eigen::MatrixXd(d * d.transpose()) : Eigen::MatrixXd(d.transpose() * d);
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(gram);  // eigenvalues ascending
  const Eigen::Index m = gram.rows();
  const double top = m > 0 ? std::max(0.0, eig.eigenvalues()(m - 1)) : 0.0;
  Eigen::Index kept = 0;
  while (kept < std::min(count, m) && eig.eigenvalues()(m - 1 - kept) > 1e-24 * top && top > 0) ++kept;
  Components c{Eigen::MatrixXd(d.rows(), kept), Eigen::MatrixXd(d.cols(), kept), Eigen::VectorXd(kept)};
  for (Eigen::Index j = 0; j < kept; ++j) {
    const double s = std::sqrt(eig.eigenvalues()(m - 1 - j));
    const Eigen::VectorXd e = eig.eigenvectors().col(m - 1 - j);
    c.s(j) = s;
    if (over_rows) {
      c.u.col(j) = e;
      c.v.col(j) = d.transpose() * e / s;
    } else {
      c.v.col(j) = e;
      c.u.col(j) = d * e / s;
    }
  }
  return c;
}

}  // namespace

BallAnimation AnimateSurface(const std::vector<double>& t_s, const SurfaceRecording& surface,
                             const BallAnimationOptions& options) {
  const size_t keys = surface.positions_m.size();
  if (keys == 0 || surface.triangles.empty()) throw std::invalid_argument("no surface recorded");
  if (keys != t_s.size()) throw std::invalid_argument("surface and trajectory samples disagree");
  const size_t n = surface.positions_m[0].size();
  BallAnimation a;
  a.t_s = t_s;
  a.triangles = surface.triangles;

  // The rest shape: the first sample (the settled ball at rest, at the release), around
  // its centroid.
  const Vec3 c0 = Centroid(surface.positions_m[0]);
  Eigen::MatrixXd rest(n, 3);
  for (size_t i = 0; i < n; ++i) rest.row(Eigen::Index(i)) = (V(surface.positions_m[0][i]) - c0).transpose();
  double radius = 0;
  for (Eigen::Index i = 0; i < rest.rows(); ++i) radius = std::max(radius, rest.row(i).norm());

  // Rigid part per key, and what is left of each key in the ball's own frame.
  std::vector<Eigen::Matrix3d> turn(keys);
  Eigen::MatrixXd deformation(Eigen::Index(keys), Eigen::Index(3 * n));
  for (size_t k = 0; k < keys; ++k) {
    const auto& x = surface.positions_m[k];
    if (x.size() != n) throw std::invalid_argument("surface samples of different sizes");
    const Vec3 c = Centroid(x);
    Eigen::MatrixXd now(n, 3);
    for (size_t i = 0; i < n; ++i) now.row(Eigen::Index(i)) = (V(x[i]) - c).transpose();
    turn[k] = BestRotation(rest, now);
    const double angle = Eigen::AngleAxisd(turn[k]).angle();
    a.max_turn_rad = std::max(a.max_turn_rad, angle);
    a.translation_m.push_back(F(c));
    const Eigen::MatrixXd local = now * turn[k];  // rows: R^T (x - c)
    for (size_t i = 0; i < n; ++i) {
      const Eigen::RowVector3d d = local.row(Eigen::Index(i)) - rest.row(Eigen::Index(i));
      a.max_deformation_m = std::max(a.max_deformation_m, d.norm());
      deformation.block(Eigen::Index(k), Eigen::Index(3 * i), 1, 3) = d;
    }
  }
  const bool turns = a.max_turn_rad * radius > options.turn_tolerance_m;
  if (turns) {
    for (const auto& r : turn) {
      const Eigen::Quaterniond q(r);
      a.rotation.push_back({float(q.x()), float(q.y()), float(q.z()), float(q.w())});
    }
  } else {  // played unturned: what the turn moved is deformation now
    for (size_t k = 0; k < keys; ++k) {
      const auto& x = surface.positions_m[k];
      const Vec3 c = V(a.translation_m[k]);
      for (size_t i = 0; i < n; ++i)
        deformation.block(Eigen::Index(k), Eigen::Index(3 * i), 1, 3) =
            (V(x[i]) - c).transpose() - rest.row(Eigen::Index(i));
    }
  }

  // Principal components of the deformation, as many as the tolerance needs.
  auto max_error = [&](const Eigen::MatrixXd& residual) {
    double worst = 0;
    for (Eigen::Index k = 0; k < residual.rows(); ++k)
      for (size_t i = 0; i < n; ++i)
        worst = std::max(worst, residual.block(k, Eigen::Index(3 * i), 1, 3).norm());
    return worst;
  };
  Eigen::MatrixXd residual = deformation;
  a.max_error_m = max_error(residual);
  int targets = 0;
  Components pc;
  if (a.max_error_m > options.tolerance_m && options.max_targets > 0) {
    pc = PrincipalComponents(deformation, options.max_targets);
    const int available = int(pc.s.size());
    while (targets < available && a.max_error_m > options.tolerance_m) {
      const Eigen::VectorXd w = pc.u.col(targets) * pc.s(targets);
      residual -= w * pc.v.col(targets).transpose();
      a.max_error_m = max_error(residual);
      ++targets;
    }
  }
  // Each target spans its weights' range, so that every weight lies in [0, 1] (importers
  // differ on weights outside it); the base mesh takes the range's low end.
  Eigen::MatrixXd base = rest;
  a.weights.assign(keys, {});
  for (int j = 0; j < targets; ++j) {
    const Eigen::VectorXd w = pc.u.col(j) * pc.s(j);
    const double lo = std::min(0.0, w.minCoeff()), hi = std::max(0.0, w.maxCoeff());
    const Eigen::VectorXd v = pc.v.col(j);
    std::vector<std::array<float, 3>> target(n);
    for (size_t i = 0; i < n; ++i) {
      const Eigen::Vector3d vi = v.segment<3>(Eigen::Index(3 * i));
      base.row(Eigen::Index(i)) += lo * vi.transpose();
      target[i] = F((hi - lo) * vi);
    }
    a.targets_m.push_back(std::move(target));
    a.rest_weights.push_back(float(-lo / (hi - lo)));
    for (size_t k = 0; k < keys; ++k) a.weights[k].push_back(float((w(Eigen::Index(k)) - lo) / (hi - lo)));
  }
  for (size_t i = 0; i < n; ++i) a.base_m.push_back(F(base.row(Eigen::Index(i)).transpose()));
  std::vector<std::array<float, 3>> rest_f(n);
  for (size_t i = 0; i < n; ++i) rest_f[i] = F(rest.row(Eigen::Index(i)).transpose());
  a.normals = Normals(rest_f, a.triangles);
  return a;
}

BallAnimation AnimateRigidSphere(const std::vector<double>& t_s,
                                 const std::vector<std::array<float, 3>>& centres_m,
                                 double radius_m, int frequency) {
  if (t_s.size() != centres_m.size() || t_s.empty())
    throw std::invalid_argument("a sphere's key times and centres disagree");
  if (frequency < 1) throw std::invalid_argument("geodesic frequency must be >= 1");
  BallAnimation a;
  a.t_s = t_s;
  a.translation_m = centres_m;
  // An icosahedron, each face split into frequency^2 triangles pushed onto the sphere;
  // vertices shared along edges are merged by their barycentric address.
  const double p = (1 + std::sqrt(5.0)) / 2;
  const std::vector<Vec3> ico = {{-1, p, 0}, {1, p, 0},  {-1, -p, 0}, {1, -p, 0},
                                 {0, -1, p}, {0, 1, p},  {0, -1, -p}, {0, 1, -p},
                                 {p, 0, -1}, {p, 0, 1},  {-p, 0, -1}, {-p, 0, 1}};
  const int faces[20][3] = {{0, 11, 5}, {0, 5, 1},  {0, 1, 7},   {0, 7, 10}, {0, 10, 11},
                            {1, 5, 9},  {5, 11, 4}, {11, 10, 2}, {10, 7, 6}, {7, 1, 8},
                            {3, 9, 4},  {3, 4, 2},  {3, 2, 6},   {3, 6, 8},  {3, 8, 9},
                            {4, 9, 5},  {2, 4, 11}, {6, 2, 10},  {8, 6, 7},  {9, 8, 1}};
  std::map<std::tuple<long, long, long>, int> index_of;
  auto vertex = [&](const Vec3& q) {
    const Vec3 u = q.normalized();
    const auto key = std::make_tuple(std::lround(u.x() * 1e6), std::lround(u.y() * 1e6),
                                     std::lround(u.z() * 1e6));
    const auto [it, added] = index_of.emplace(key, int(a.base_m.size()));
    if (added) {
      a.base_m.push_back(F(u * radius_m));
      a.normals.push_back(F(u));
    }
    return it->second;
  };
  const int f = frequency;
  for (const auto& face : faces) {
    const Vec3 A = ico[size_t(face[0])], B = ico[size_t(face[1])], C = ico[size_t(face[2])];
    auto at = [&](int i, int j) { return vertex(A + (B - A) * (double(i) / f) + (C - A) * (double(j) / f)); };
    for (int i = 0; i < f; ++i)
      for (int j = 0; i + j < f; ++j) {
        a.triangles.push_back({at(i, j), at(i + 1, j), at(i, j + 1)});
        if (i + j + 2 <= f) a.triangles.push_back({at(i + 1, j), at(i + 1, j + 1), at(i, j + 1)});
      }
  }
  return a;
}

}  // namespace bouncefit
