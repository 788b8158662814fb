#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>

#include "dynid/model/model.hpp"

namespace dynid {

/// One modified Denavit–Hartenberg row (Khalil–Kleinfinger notation; Craig's α_{i−1}, a_{i−1},
/// θ_i, d_i are the same frames with α = α_{i−1}, d = a_{i−1}, r = d_i).
struct MdhRow {
  int sigma = 0;       ///< 0 revolute (q adds to theta), 1 prismatic (q adds to r)
  double alpha = 0.0;  ///< twist about x of the antecedent frame [rad]
  double d = 0.0;      ///< distance along x of the antecedent frame [m]
  double theta = 0.0;  ///< constant angle about z_j (offset of the joint variable) [rad]
  double r = 0.0;      ///< constant distance along z_j (offset of the joint variable) [m]
};

/// Fixed part of a modified DH row in the Model's joint form. Identity:
/// RotX(α)·TransX(d)·RotZ(θ+q)·TransZ(r) = (R_PJ, p_PJ)·RotZ(q) for a revolute row and
/// RotX(α)·TransX(d)·RotZ(θ)·TransZ(r+q) = (R_PJ, p_PJ)·TransZ(q) for a prismatic one, with
/// R_PJ = RotX(α)·RotZ(θ), p_PJ = (d, 0, 0) + RotX(α)·(0, 0, r), axis = z_j (Khalil & Kleinfinger
/// 1986; docs/methods/model.md, "MDH"). The row's name, parent, inertia and limits are not set.
Joint mdh_joint(const MdhRow& row);

/// Loads a YAML robot description and returns a finalized Model. Two forms
/// (docs/methods/model.md, "YAML model"):
/// - `joints:` an MDH table, one map per row with `sigma` and `alpha, d, theta, r` (KK) or
///   `alpha_prev, a_prev, theta, d` (Craig), optional `name`, `link`, `parent` (1-based, 0 = base,
///   default previous row), `limits {lower, upper, velocity, effort}`, inertia as
///   `inertia: [XX,XY,XZ,YY,YZ,ZZ,MX,MY,MZ,M]` about the frame origin or as `mass`, `com`,
///   `inertia_com: [XX,XY,XZ,YY,YZ,ZZ]` about the centre of mass, and `Ia, Fv, Fc, Fo`; optional
///   top-level `base: {xyz, rpy}` placing the frames of the rows whose parent is the base.
/// - `urdf: relative/or/absolute.urdf` with optional `friction: {joint: {Ia, Fv, Fc, Fo}}`.
/// Both accept `name`, `gravity: [gx, gy, gz]` (base frame, m/s²), and either
/// `transmission: {N: n×n rows, q_offset: [n]}` or `gear_ratios: [n]` (N = diag).
/// Throws dynid::Error naming the key and row at fault (missing key, unknown key, NaN/Inf, wrong
/// sizes, negative mass) and every error of Model::finalize / load_urdf; a non-physical inertia
/// is a line of `warnings` when it is not null (Model::finalize). Model::urdf is the
/// `urdf:` file, resolved.
Model load_yaml_model(const std::string& path, std::vector<std::string>* warnings = nullptr);

/// Same as load_yaml_model for YAML text; `source` names it in messages and Model::source, and a
/// relative `urdf:` path is resolved against `base_dir`.
Model parse_yaml_model(const std::string& yaml, const std::string& source,
                       const std::string& base_dir, std::vector<std::string>* warnings = nullptr);

}  // namespace dynid
