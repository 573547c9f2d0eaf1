#pragma once

#include <Eigen/Core>
#include <Eigen/Dense>
#include <Eigen/SparseCore>
#include <memory>
#include <string>
#include <vector>

namespace msfem::massspring {

/// Which linearisation of the force a Jacobian call returns.
enum class Linearisation {
  exact,    ///< the true derivative (what the finite-difference test checks)
  definite  ///< ∂f/∂x made negative semi-definite (compressed springs' transverse term and the
            ///< damper's geometric term dropped, Baraff & Witkin 1998 / Choi & Ko 2002), so that
            ///< M - h ∂f/∂v - h² ∂f/∂x is SPD and conjugate gradients apply
};

using Triplets = std::vector<Eigen::Triplet<double>>;

/// One force-model interface (Vega's ForceModel, SOFA's ForceField): everything an integrator or a
/// static solver needs from a set of forces acting on n nodes. State vectors are node-major,
/// x = (x0, y0, z0, x1, ...), of length num_dofs() = 3n. All "add_" calls accumulate into their
/// output, which must already have the right size.
class ForceModel {
 public:
  virtual ~ForceModel() = default;

  virtual int num_dofs() const = 0;

  /// f += f(x, v)
  virtual void add_force(const Eigen::VectorXd& x, const Eigen::VectorXd& v,
                         Eigen::VectorXd& f) const = 0;

  /// Potential energy of the conservative part, with f_conservative = -∇U.
  virtual double potential_energy(const Eigen::VectorXd& x) const = 0;

  /// df += (∂f/∂x)(x, v) · dx, matrix-free.
  virtual void add_dfdx_product(const Eigen::VectorXd& x, const Eigen::VectorXd& v,
                                const Eigen::VectorXd& dx, Eigen::VectorXd& df,
                                Linearisation mode = Linearisation::exact) const = 0;

  /// df += (∂f/∂v)(x) · dv, matrix-free.
  virtual void add_dfdv_product(const Eigen::VectorXd& x, const Eigen::VectorXd& dv,
                                Eigen::VectorXd& df) const = 0;

  /// Triplets of ∂f/∂x (duplicates are summed by setFromTriplets).
  virtual void add_dfdx_triplets(const Eigen::VectorXd& x, const Eigen::VectorXd& v,
                                 Triplets& triplets,
                                 Linearisation mode = Linearisation::exact) const = 0;

  /// Triplets of ∂f/∂v.
  virtual void add_dfdv_triplets(const Eigen::VectorXd& x, Triplets& triplets) const = 0;

  // Conveniences built on the virtual calls.
  Eigen::VectorXd force(const Eigen::VectorXd& x, const Eigen::VectorXd& v) const;
  Eigen::SparseMatrix<double> dfdx(const Eigen::VectorXd& x, const Eigen::VectorXd& v,
                                   Linearisation mode = Linearisation::exact) const;
  Eigen::SparseMatrix<double> dfdv(const Eigen::VectorXd& x) const;
};

/// One of the forces a MechanicalSystem sums (its springs, volume preservation, the tool's contact,
/// ...): a ForceModel over the system's nodes that also says which nodes it acts on and which of
/// its coefficients a fit may scale. Fields are immutable once in a model (copies of the model
/// share them); a changed field is a new one put in its place.
class ForceField : public ForceModel {
 public:
  /// The nodes whose forces this field sets, and the only ones whose x, v (and, in the products,
  /// dx) the field reads (the static solver's node relaxation leaves them to Newton, unless it
  /// knows the field; the fast steppers gather x, v and dx at these nodes only).
  virtual const std::vector<int>& nodes() const = 0;
  /// What messages call this field ("volume preservation", "tool contact", ...).
  virtual std::string name() const { return "force field"; }
  /// Names of the coefficient groups a fit may scale, each one factor on a set of stiffnesses
  /// (volume preservation: "volume"); none by default.
  virtual std::vector<std::string> coefficient_groups() const { return {}; }
  /// This field with `group`'s coefficients multiplied by `factor`; throws ModelError for a group
  /// it does not have.
  virtual std::shared_ptr<const ForceField> scaled(const std::string& group, double factor) const;
  /// The coefficients `group` scales, for a fit to report (their mean, before and after), and
  /// their unit. By default one coefficient 1 without unit: the fit reports the factor alone.
  virtual std::vector<double> coefficients(const std::string& group) const;
  virtual std::string coefficient_unit(const std::string& /*group*/) const { return "1"; }
  /// True for a field whose energy is a sum of one term per node, each depending on that node's
  /// position alone (a sphere's contact with nodes): the static solver then relaxes its nodes one
  /// at a time with their springs (add_node_term). False by default: the field's nodes are left to
  /// the global Newton iterations.
  virtual bool nodewise() const { return false; }
  /// For a nodewise field: node `node`'s term at position p, its force added to f and its
  /// stiffness -∂f/∂p to k; returns the term's energy.
  virtual double add_node_term(int /*node*/, const Eigen::Vector3d& /*p*/, Eigen::Vector3d& /*f*/,
                               Eigen::Matrix3d& /*k*/) const {
    return 0.0;
  }
  /// Part `part` of `parts` of add_force, so that threads each adding one part into their own f
  /// together add the whole force (the fast explicit stepper shares a field among its threads this
  /// way). By default part 0 is the whole force and the other parts are nothing.
  virtual void add_force_part(const Eigen::VectorXd& x, const Eigen::VectorXd& v,
                              Eigen::VectorXd& f, int part, int parts) const {
    (void)parts;
    if (part == 0) add_force(x, v, f);
  }
  /// Part `part` of `parts` of add_dfdx_product, shared among threads as add_force_part is (the
  /// fast implicit stepper's CG products). By default part 0 is the whole product.
  virtual void add_dfdx_product_part(const Eigen::VectorXd& x, const Eigen::VectorXd& v,
                                     const Eigen::VectorXd& dx, Eigen::VectorXd& df,
                                     Linearisation mode, int part, int parts) const {
    (void)parts;
    if (part == 0) add_dfdx_product(x, v, dx, df, mode);
  }
  /// blocks[i] += cx (∂f/∂x)_ii + cv (∂f/∂v)_ii, the 3x3 diagonal blocks at the field's nodes i
  /// (`blocks` has one per model node): what a block-Jacobi preconditioner of M - h D - h² K
  /// needs. By default taken from the triplets, which suits a field on a few nodes.
  virtual void add_diagonal_blocks(const Eigen::VectorXd& x, const Eigen::VectorXd& v, double cx,
                                   double cv, std::vector<Eigen::Matrix3d>& blocks,
                                   Linearisation mode) const;

  /// ∂f/∂x at the state held in x and v, kept for many products: the fast implicit stepper's CG
  /// multiplies with the same tangent a score of times per step. Set and multiplied in parts, as
  /// add_dfdx_product_part is; a part's products read only what the same part set, so a thread
  /// that has set its part may multiply at once.
  class Tangent {
   public:
    virtual ~Tangent() = default;
    /// Part `part` of `parts` of the tangent at the x and v it was made with, as they are now.
    virtual void set_part(int part, int parts) = 0;
    /// Part `part` of `parts` of df += (∂f/∂x) dx, with the parts of set_part.
    virtual void add_product_part(const Eigen::VectorXd& dx, Eigen::VectorXd& df, int part,
                                  int parts) const = 0;
    /// Part `part` of `parts` of add_diagonal_blocks(x, v, cx, cv, blocks, mode): threads that
    /// each add a part into their own `blocks` together add the whole.
    virtual void add_diagonal_blocks_part(double cx, double cv,
                                          std::vector<Eigen::Matrix3d>& blocks, int part,
                                          int parts) const = 0;
    /// Part `part` of `parts` of two products in one pass, df1 += (∂f/∂x) dx1 and
    /// df2 += (∂f/∂x) dx2 (by default two add_product_part calls).
    virtual void add_product_pair_part(const Eigen::VectorXd& dx1, Eigen::VectorXd& df1,
                                       const Eigen::VectorXd& dx2, Eigen::VectorXd& df2, int part,
                                       int parts) const {
      add_product_part(dx1, df1, part, parts);
      add_product_part(dx2, df2, part, parts);
    }
    /// Part `part` of `parts` of the start of a backward-Euler step in one pass, for a tangent
    /// that can do it while each element's data is at hand: set_part(part, parts), then
    /// f += f(x, v) + (∂f/∂x) dx1, df2 += (∂f/∂x) dx2 and add_diagonal_blocks_part(cx, cv,
    /// blocks, part, parts). False, nothing done (by default): the caller makes those calls.
    virtual bool start_part(const Eigen::VectorXd& /*dx1*/, Eigen::VectorXd& /*f*/,
                            const Eigen::VectorXd& /*dx2*/, Eigen::VectorXd& /*df2*/, double /*cx*/,
                            double /*cv*/, std::vector<Eigen::Matrix3d>& /*blocks*/, int /*part*/,
                            int /*parts*/) {
      return false;
    }
    /// Part `part` of `parts` of the field's force at the tangent's state, f += f(x, v), from
    /// what set_part found there (a volume's gradient holds its force too). False, f untouched,
    /// where the tangent keeps nothing that gives it: the caller asks the field
    /// (ForceField::add_force_part).
    virtual bool add_force_part(Eigen::VectorXd& /*f*/, int /*part*/, int /*parts*/) const {
      return false;
    }
    /// Rows instead of parts, for a caller that shares the nodes among its threads: plan p is to
    /// give the rows of the nodes in plans[p], each row whole, so that no thread sums other
    /// threads' parts. The tangent may lay its work out in the plans' order (the first plan's
    /// nodes first). False, nothing planned, where the tangent has no rows (by default) or its
    /// field has a velocity term (∂f/∂v ≠ 0), which rows do not give. Called before set_part.
    virtual bool plan_rows(const std::vector<std::vector<int>>& /*plans*/) { return false; }
    /// work[i] += what a product costs at node i's row, in spring slots (one spring seen from one
    /// end in the fast stepper's kernels), so that a caller who shares the rows among threads
    /// gives each an equal share; nothing by default (a field whose products cost little).
    virtual void add_row_work(std::vector<double>& /*work*/) const {}
    /// df += (∂f/∂x) dx at the rows of plan `plan`, the other entries untouched, once set_part has
    /// run for every part; dx must hold every one of the field's nodes.
    virtual void add_product_rows(const Eigen::VectorXd& /*dx*/, Eigen::VectorXd& /*df*/,
                                  int /*plan*/) const {}
    /// Whether the tangent's product by rows can read the direction from the caller's own
    /// records (add_product_rows_records; by default not): a caller that holds it so saves the
    /// tangent a copy of the whole direction before each product.
    virtual bool reads_direction_records() const { return false; }
    /// Node i's record in the records add_product_rows_records reads starts at
    /// 4 record_of_node[i] (x y z, then one value it does not read). Called after plan_rows.
    virtual void set_record_order(const std::vector<int>& /*record_of_node*/) {}
    /// df += scale (∂f/∂x) dx at the rows of plan `plan`, as add_product_rows, with
    /// dx[3 i + c] = dx_records[4 record_of_node[i] + c] at every one of the field's nodes i.
    virtual void add_product_rows_records(const double* /*dx_records*/, double /*scale*/,
                                          Eigen::VectorXd& /*df*/, int /*plan*/) const {}
    /// Whether start_rows gives the start of a step (by default not: the caller takes it by
    /// parts, start_part or the calls it stands for).
    virtual bool starts_by_rows() const { return false; }
    /// start_part by rows: at the rows of plan `plan`, once set_part has run for every part,
    /// f += f(x, v) + (∂f/∂x) dx1, df2 += (∂f/∂x) dx2 and blocks[i] += cx (∂f/∂x)_ii (the field
    /// has no velocity term where it has rows), the other entries untouched.
    virtual void start_rows(const Eigen::VectorXd& /*dx1*/, Eigen::VectorXd& /*f*/,
                            const Eigen::VectorXd& /*dx2*/, Eigen::VectorXd& /*df2*/, double /*cx*/,
                            std::vector<Eigen::Matrix3d>& /*blocks*/, int /*plan*/) const {}
  };
  /// A tangent at the state in x and v, which must outlive it. By default it multiplies with
  /// add_dfdx_product_part at each product, which suits a field whose product costs little beside
  /// its state (a tool's contact).
  virtual std::unique_ptr<Tangent> tangent(const Eigen::VectorXd& x, const Eigen::VectorXd& v,
                                           Linearisation mode) const;
};

}  // namespace msfem::massspring
