#include "msfem/massspring/surface_contact.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <string>
#include <utility>

#include "geometry/kd_tree.hpp"
#include "msfem/massspring/errors.hpp"
#include "msfem/massspring/mass_spring_model.hpp"

namespace msfem::massspring {

namespace {

/// Sub-edges of at most a sixth of the tool's radius: the contact disc of a shallow press spans a
/// few of them even on a single triangle.
constexpr double sub_edges_per_radius = 6.0;
constexpr int max_subdivisions = 48;

}  // namespace

struct SurfaceContactForceField::BroadPhase {
  Eigen::MatrixX3d centroids;
  detail::PointCloud cloud{centroids};
  detail::KdTree tree;

  explicit BroadPhase(Eigen::MatrixX3d points)
      : centroids(std::move(points)),
        tree(3, cloud, nanoflann::KDTreeSingleIndexAdaptorParams(10)) {
    tree.buildIndex();
  }

  std::vector<int> triangles_near(const Eigen::Vector3d& center, double radius) const {
    std::vector<std::pair<std::size_t, double>> found;
    const double query[3] = {center.x(), center.y(), center.z()};
    tree.radiusSearch(query, radius * radius, found, nanoflann::SearchParams());
    std::vector<int> result;
    result.reserve(found.size());
    for (const auto& item : found)
      result.push_back(int(item.first));
    return result;
  }
};

SurfaceContactForceField::SurfaceContactForceField(const Eigen::MatrixX3d& rest_positions,
                                                   Eigen::MatrixX3i triangles, SphereTool tool,
                                                   double pressure_penalty)
    : num_nodes_(int(rest_positions.rows())),
      rest_positions_(rest_positions),
      triangles_(std::move(triangles)),
      tool_(tool),
      pressure_penalty_(pressure_penalty) {
  if (!(tool_.radius > 0.0) || !std::isfinite(tool_.radius) || !tool_.center.allFinite())
    throw ModelError("surface contact: the tool needs a finite centre and a finite radius > 0");
  if (!(pressure_penalty_ > 0.0) || !std::isfinite(pressure_penalty_))
    throw ModelError("surface contact: pressure penalty must be finite and > 0");
  if (triangles_.rows() == 0) throw ModelError("surface contact: no triangles");
  if (triangles_.minCoeff() < 0 || triangles_.maxCoeff() >= num_nodes_)
    throw ModelError("surface contact: a triangle names a node outside the model");
  Eigen::MatrixX3d centroids(triangles_.rows(), 3);
  std::vector<char> on_surface(std::size_t(num_nodes_), 0);
  double total_area = 0.0;
  for (Eigen::Index t = 0; t < triangles_.rows(); ++t) {
    const Eigen::Vector3d a = rest_positions_.row(triangles_(t, 0)).transpose();
    const Eigen::Vector3d b = rest_positions_.row(triangles_(t, 1)).transpose();
    const Eigen::Vector3d c = rest_positions_.row(triangles_(t, 2)).transpose();
    const Eigen::Vector3d centroid = (a + b + c) / 3.0;
    centroids.row(t) = centroid.transpose();
    rest_area_.push_back(0.5 * (b - a).cross(c - a).norm());
    total_area += rest_area_.back();
    const double longest = std::max({(b - a).norm(), (c - b).norm(), (a - c).norm()});
    subdivisions_.push_back(std::clamp(
        int(std::ceil(longest * sub_edges_per_radius / tool_.radius)), 1, max_subdivisions));
    largest_triangle_radius_ =
        std::max(largest_triangle_radius_,
                 std::max({(a - centroid).norm(), (b - centroid).norm(), (c - centroid).norm()}));
    for (int k = 0; k < 3; ++k)
      on_surface[std::size_t(triangles_(t, k))] = 1;
  }
  for (int i = 0; i < num_nodes_; ++i)
    if (on_surface[std::size_t(i)]) nodes_.push_back(i);
  mean_node_area_ = total_area / double(nodes_.size());
  broad_phase_ = std::make_shared<const BroadPhase>(std::move(centroids));
}

void SurfaceContactForceField::set_pressure_penalty(double pressure_penalty) {
  if (!(pressure_penalty > 0.0) || !std::isfinite(pressure_penalty))
    throw ModelError("surface contact: pressure penalty must be finite and > 0");
  pressure_penalty_ = pressure_penalty;
}

template <class Visit>
void SurfaceContactForceField::for_each_contact_point(const Eigen::VectorXd& x, Visit&& visit,
                                                      int part, int parts) const {
  // Triangles whose rest centroid could have moved to within reach of the tool.
  double moved = 0.0;
  for (int i : nodes_)
    moved = std::max(moved, (x.segment<3>(3 * i) - rest_positions_.row(i).transpose()).norm());
  const double r = tool_.radius;
  const std::vector<int> near =
      broad_phase_->triangles_near(tool_.center, r + largest_triangle_radius_ + moved);
  for (std::size_t k = std::size_t(part); k < near.size(); k += std::size_t(parts)) {
    const int t = near[k];
    const Eigen::Vector3d xa = x.segment<3>(3 * triangles_(t, 0));
    const Eigen::Vector3d xb = x.segment<3>(3 * triangles_(t, 1));
    const Eigen::Vector3d xc = x.segment<3>(3 * triangles_(t, 2));
    const Eigen::Vector3d centroid = (xa + xb + xc) / 3.0;
    const double reach =
        std::max({(xa - centroid).norm(), (xb - centroid).norm(), (xc - centroid).norm()});
    if ((centroid - tool_.center).norm() >= r + reach) continue;
    const int n = subdivisions_[std::size_t(t)];
    const double coefficient = pressure_penalty_ * rest_area_[std::size_t(t)] / double(n * n);
    // Centroids of the n^2 sub-triangles: "up" ones at ((3i+1)/3n, (3j+1)/3n), "down" ones at
    // ((3i+2)/3n, (3j+2)/3n) in the coordinates of the second and third vertex.
    const auto point = [&](double u, double v) {
      const double b0 = 1.0 - u - v;
      const Eigen::Vector3d w = b0 * xa + u * xb + v * xc - tool_.center;
      const double rho = w.norm();
      if (rho < r && rho > 0.0) visit(t, b0, u, v, coefficient, w);
    };
    for (int i = 0; i < n; ++i)
      for (int j = 0; i + j < n; ++j) {
        point((3 * i + 1) / (3.0 * n), (3 * j + 1) / (3.0 * n));
        if (i + j <= n - 2) point((3 * i + 2) / (3.0 * n), (3 * j + 2) / (3.0 * n));
      }
  }
}

void SurfaceContactForceField::add_force(const Eigen::VectorXd& x, const Eigen::VectorXd& v,
                                         Eigen::VectorXd& f) const {
  add_force_part(x, v, f, 0, 1);
}

void SurfaceContactForceField::add_force_part(const Eigen::VectorXd& x, const Eigen::VectorXd&,
                                              Eigen::VectorXd& f, int part, int parts) const {
  for_each_contact_point(
      x,
      [&](int t, double b0, double b1, double b2, double coefficient, const Eigen::Vector3d& w) {
        const double rho = w.norm();
        const Eigen::Vector3d push = coefficient * (tool_.radius - rho) / rho * w;
        const double b[3] = {b0, b1, b2};
        for (int k = 0; k < 3; ++k)
          f.segment<3>(3 * triangles_(t, k)) += b[k] * push;
      },
      part, parts);
}

double SurfaceContactForceField::potential_energy(const Eigen::VectorXd& x) const {
  double energy = 0.0;
  for_each_contact_point(
      x, [&](int, double, double, double, double coefficient, const Eigen::Vector3d& w) {
        const double gap = tool_.radius - w.norm();
        energy += 0.5 * coefficient * gap * gap;
      });
  return energy;
}

Eigen::Matrix3d SurfaceContactForceField::block(const Eigen::Vector3d& w,
                                                Linearisation mode) const {
  // As for a node: d[(r - ρ) w/ρ]/dw = -n nᵀ + (r - ρ)/ρ (I - n nᵀ); the definite form drops the
  // positive second term.
  const double rho = w.norm();
  const Eigen::Vector3d n = w / rho;
  const Eigen::Matrix3d nn = n * n.transpose();
  Eigen::Matrix3d result = -nn;
  if (mode == Linearisation::exact)
    result += (tool_.radius - rho) / rho * (Eigen::Matrix3d::Identity() - nn);
  return result;
}

void SurfaceContactForceField::add_dfdx_product(const Eigen::VectorXd& x, const Eigen::VectorXd& v,
                                                const Eigen::VectorXd& dx, Eigen::VectorXd& df,
                                                Linearisation mode) const {
  add_dfdx_product_part(x, v, dx, df, mode, 0, 1);
}

void SurfaceContactForceField::add_dfdx_product_part(const Eigen::VectorXd& x,
                                                     const Eigen::VectorXd&,
                                                     const Eigen::VectorXd& dx, Eigen::VectorXd& df,
                                                     Linearisation mode, int part,
                                                     int parts) const {
  for_each_contact_point(
      x,
      [&](int t, double b0, double b1, double b2, double coefficient, const Eigen::Vector3d& w) {
        const double b[3] = {b0, b1, b2};
        Eigen::Vector3d moved = Eigen::Vector3d::Zero();
        for (int l = 0; l < 3; ++l)
          moved += b[l] * dx.segment<3>(3 * triangles_(t, l));
        const Eigen::Vector3d change = coefficient * (block(w, mode) * moved);
        for (int k = 0; k < 3; ++k)
          df.segment<3>(3 * triangles_(t, k)) += b[k] * change;
      },
      part, parts);
}

// The contact points inside the tool at set_part, per part: a product gathers and scatters over
// them alone. Parts are set and read by one thread each, so each keeps its own list.
class KeptContactTangent final : public ForceField::Tangent {
 public:
  KeptContactTangent(const SurfaceContactForceField& field, const Eigen::VectorXd& x,
                     Linearisation mode)
      : field_(&field), x_(&x), mode_(mode), points_(kMaxParts) {}

  void set_part(int part, int parts) override {
    if (parts > kMaxParts)
      throw ModelError("surface contact tangent: at most " + std::to_string(kMaxParts) + " parts");
    if (part == 0) parts_ = parts;  // read by the rows after every part is set
    std::vector<Point>& points = points_[std::size_t(part)];
    points.clear();
    field_->for_each_contact_point(
        *x_,
        [&](int t, double b0, double b1, double b2, double coefficient, const Eigen::Vector3d& w) {
          const double rho = w.norm();
          Point p;
          for (int k = 0; k < 3; ++k)
            p.offset[k] = 3 * field_->triangles_(t, k);
          p.b = Eigen::Vector3d(b0, b1, b2);
          p.push = coefficient * (field_->tool_.radius - rho) / rho * w;
          p.stiffness = coefficient * field_->block(w, mode_);
          points.push_back(p);
        },
        part, parts);
  }

  void add_product_part(const Eigen::VectorXd& dx, Eigen::VectorXd& df, int part,
                        int) const override {
    for (const Point& p : points_[std::size_t(part)]) {
      Eigen::Vector3d moved = Eigen::Vector3d::Zero();
      for (int l = 0; l < 3; ++l)
        moved += p.b[l] * dx.segment<3>(p.offset[l]);
      const Eigen::Vector3d change = p.stiffness * moved;
      for (int k = 0; k < 3; ++k)
        df.segment<3>(p.offset[k]) += p.b[k] * change;
    }
  }

  // A row sums the points on the triangles at its node; the points are few (those inside the
  // tool), so each plan walks every part's list and keeps its own nodes' share.
  bool plan_rows(const std::vector<std::vector<int>>& plans) override {
    in_plan_.assign(plans.size(), std::vector<char>(std::size_t(x_->size() / 3), 0));
    for (std::size_t plan = 0; plan < plans.size(); ++plan)
      for (int node : plans[plan])
        in_plan_[plan][std::size_t(node)] = 1;
    return true;
  }

  void add_product_rows(const Eigen::VectorXd& dx, Eigen::VectorXd& df, int plan) const override {
    const std::vector<char>& in = in_plan_[std::size_t(plan)];
    for (int part = 0; part < parts_; ++part)
      for (const Point& p : points_[std::size_t(part)]) {
        const bool at[3] = {in[std::size_t(p.offset[0] / 3)] != 0,
                            in[std::size_t(p.offset[1] / 3)] != 0,
                            in[std::size_t(p.offset[2] / 3)] != 0};
        if (!at[0] && !at[1] && !at[2]) continue;
        Eigen::Vector3d moved = Eigen::Vector3d::Zero();
        for (int l = 0; l < 3; ++l)
          moved += p.b[l] * dx.segment<3>(p.offset[l]);
        const Eigen::Vector3d change = p.stiffness * moved;
        for (int k = 0; k < 3; ++k)
          if (at[k]) df.segment<3>(p.offset[k]) += p.b[k] * change;
      }
  }

  // Frictionless: no velocity term, cv does not enter.
  void add_diagonal_blocks_part(double cx, double, std::vector<Eigen::Matrix3d>& blocks, int part,
                                int) const override {
    for (const Point& p : points_[std::size_t(part)])
      for (int k = 0; k < 3; ++k)
        blocks[std::size_t(p.offset[k] / 3)] += (cx * p.b[k] * p.b[k]) * p.stiffness;
  }

  bool add_force_part(Eigen::VectorXd& f, int part, int) const override {
    for (const Point& p : points_[std::size_t(part)])
      for (int k = 0; k < 3; ++k)
        f.segment<3>(p.offset[k]) += p.b[k] * p.push;
    return true;
  }

 private:
  static constexpr int kMaxParts = 64;  // the fast steppers' most threads
  struct Point {
    int offset[3];              // 3 × the triangle's nodes
    Eigen::Vector3d b;          // barycentric weights
    Eigen::Vector3d push;       // the point's force on the surface
    Eigen::Matrix3d stiffness;  // coefficient × ∂(push)/∂x(s)
  };
  const SurfaceContactForceField* field_;
  const Eigen::VectorXd* x_;
  Linearisation mode_;
  std::vector<std::vector<Point>> points_;  // per part
  int parts_ = 0;                           // of the last set_part
  std::vector<std::vector<char>> in_plan_;  // per plan and node: whether its row is the plan's
};

std::unique_ptr<ForceField::Tangent> SurfaceContactForceField::tangent(const Eigen::VectorXd& x,
                                                                       const Eigen::VectorXd&,
                                                                       Linearisation mode) const {
  return std::make_unique<KeptContactTangent>(*this, x, mode);
}

void SurfaceContactForceField::add_dfdx_triplets(const Eigen::VectorXd& x, const Eigen::VectorXd&,
                                                 Triplets& triplets, Linearisation mode) const {
  for_each_contact_point(
      x, [&](int t, double b0, double b1, double b2, double coefficient, const Eigen::Vector3d& w) {
        const double b[3] = {b0, b1, b2};
        const Eigen::Matrix3d k = coefficient * block(w, mode);
        for (int p = 0; p < 3; ++p)
          for (int q = 0; q < 3; ++q)
            for (int r = 0; r < 3; ++r)
              for (int c = 0; c < 3; ++c)
                triplets.emplace_back(3 * triangles_(t, p) + r, 3 * triangles_(t, q) + c,
                                      b[p] * b[q] * k(r, c));
      });
}

double SurfaceContactForceField::contact_area(const Eigen::VectorXd& x) const {
  double area = 0.0;
  for_each_contact_point(x, [&](int, double, double, double, double coefficient,
                                const Eigen::Vector3d&) { area += coefficient; });
  return area / pressure_penalty_;
}

double activate_surface_contact(MassSpringModel& model, const ToolIndentation& indent,
                                double pressure_penalty) {
  const SpringNetwork& net = model.network();
  SurfaceContactForceField contact(net.rest_positions, net.surface_triangles, indent.tool(),
                                   pressure_penalty > 0.0 ? pressure_penalty : 1.0);
  if (pressure_penalty <= 0.0) {
    // At κ = 1 the nodal stiffness is a mean node's area.
    pressure_penalty = 1000.0 * stiffest_surface_node(model) / contact.penalty_stiffness();
    contact.set_pressure_penalty(pressure_penalty);
  }
  model.set_contact(contact);
  return pressure_penalty;
}

}  // namespace msfem::massspring
