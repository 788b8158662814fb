#pragma once

#include <limits>
#include <string>
#include <vector>

#include <Eigen/Core>

namespace dynid {

/// One-DoF joint kinds. Fixed joints never reach a Model: loaders merge them into the parent link.
enum class JointType { kRevolute, kPrismatic };

/// Number of standard inertial parameters per link (docs/design.md section 3).
inline constexpr int kLinkParams = 10;

/// Largest number of moving joints a model may have (docs/cli.md, "Input size limits"). The
/// regrouping of a chain is transitive, so its base-parameter expressions and K_d hold O(n²) terms:
/// `model --base` of a 1000-joint chain takes 6 s and 0.7 GB, of 2000 joints 22 s and 2.6 GB, of
/// 5000 joints 100 s and 7.6 GB (docs/performance.md). Every identification needs them.
inline constexpr int kMaxJoints = 1000;

/// Standard inertial parameters of one link, in link frame j, about the link ORIGIN, in the order
/// XX XY XZ YY YZ ZZ MX MY MZ M (kg·m², kg·m, kg). MX = m·c_x.
using LinkParams = Eigen::Matrix<double, kLinkParams, 1>;

/// Joint-side actuator and friction terms:
/// tau += Ia·ddq + Fv·dq + Fc·sign(dq) + Fo + Fva·|dq| + Fca·|sign(dq)|.
/// The last two are seed 2 eq. 2's asymmetry: Fvp,n = Fv ± Fva and Fcp,n = Fc ± Fca.
struct JointFriction {
  double Ia = 0.0;   ///< actuator (rotor) inertia reflected to the joint [kg·m² or kg]
  double Fv = 0.0;   ///< viscous coefficient, mean of both directions [N·m·s/rad or N·s/m]
  double Fc = 0.0;   ///< Coulomb level, mean of both directions [N·m or N]
  double Fo = 0.0;   ///< constant offset [N·m or N]
  double Fva = 0.0;  ///< viscous asymmetry (Fvp − Fvn)/2 [N·m·s/rad or N·s/m]
  double Fca = 0.0;  ///< Coulomb asymmetry (Fcp − Fcn)/2 [N·m or N]
};

/// Joint limits; absent limits are +/- infinity.
struct JointLimits {
  double lower = -std::numeric_limits<double>::infinity();    ///< [rad or m]
  double upper = std::numeric_limits<double>::infinity();     ///< [rad or m]
  double velocity = std::numeric_limits<double>::infinity();  ///< [rad/s or m/s]
  double effort = std::numeric_limits<double>::infinity();    ///< [N·m or N]
};

/// Joint j connects link parent (-1 = the fixed base) to link j. Frame convention (URDF): the pose
/// of link frame j in its parent's frame is X_PJ(q) = (R_PJ, p_PJ) · motion(axis, q), where the
/// motion is a rotation by q about `axis` (revolute) or a translation q·axis (prismatic), axis
/// given in frame j. Modified DH rows map onto the same form (docs/notation.md).
struct Joint {
  std::string name;
  std::string link_name;
  JointType type = JointType::kRevolute;
  int parent = -1;
  Eigen::Matrix3d R_PJ = Eigen::Matrix3d::Identity();
  Eigen::Vector3d p_PJ = Eigen::Vector3d::Zero();
  Eigen::Vector3d axis = Eigen::Vector3d::UnitZ();  ///< unit vector in frame j
  JointLimits limits;
  JointFriction friction;
};

/// Motor <-> joint transmission (docs/design.md section 3): q_motor = N·(q - q_offset), so
/// q = N⁻¹·q_motor + q_offset, and tau_joint = Nᵀ·tau_motor. N is n×n, identity by default.
struct Transmission {
  Eigen::MatrixXd N;         ///< n×n, invertible
  Eigen::VectorXd q_offset;  ///< n, added to the joint angles after N⁻¹ [rad or m]
  bool is_identity() const;
};

/// A moving joint of the robot file held fixed at a value (lock_joints(), issue 26 item 1).
struct JointLock {
  std::string name;    ///< the joint's name in the robot file
  double value = 0.0;  ///< the position it is held at [rad or m]
};

/// An immutable kinematic tree with inertial, actuator and friction parameters. Built by the
/// loaders (URDF, MDH YAML) or by hand followed by finalize(); every algorithm takes it by const&.
/// Joint order is the index j used everywhere (columns, parameter names): parents precede children.
struct Model {
  std::string name;
  std::vector<Joint> joints;
  std::vector<LinkParams> links;             ///< one per joint, standard order
  Eigen::Vector3d gravity{0.0, 0.0, -9.81};  ///< in the base frame [m/s²]
  Transmission transmission;
  std::string source;  ///< file or built-in name it came from
  /// The URDF file the frames were read from (a .urdf model, or the `urdf:` of a YAML model);
  /// empty for MDH tables. export edits this file, so its <visual> and meshes are kept.
  std::string urdf;
  /// Moving joints of the robot file held fixed (lock_joints()), in file order; empty: none.
  std::vector<JointLock> locked_joints;

  int dof() const { return static_cast<int>(joints.size()); }

  /// Checks consistency (parents precede children, unit axes, orthonormal rotations, sizes,
  /// physical inertias: m ≥ 0 and the rotational inertia about the centre of mass positive
  /// semi-definite with the triangle inequality), the joint count (at most kMaxJoints), duplicate
  /// joint names, and an invertible transmission (scale-invariant test, linear time for a diagonal
  /// N) and fills defaults (identity transmission). Throws dynid::Error naming the joint or link at
  /// fault. A link inertia that is not physical (an inertia about the centre of mass that is not
  /// positive semi-definite or breaks the triangle inequality) is an error when
  /// `inertia_warnings` is null, else one line appended to it (naming the link and the size of
  /// the violation) and the model is kept: vendor URDFs break it by a few percent. A negative mass
  /// and a first moment without mass stay errors.
  void finalize(std::vector<std::string>* inertia_warnings = nullptr);

  /// The standard parameter vector theta (10 per link, docs/design.md section 3 order), size 10·n.
  Eigen::VectorXd standard_parameters() const;

  /// Names `XX1 XY1 ... M1 XX2 ...` matching standard_parameters().
  std::vector<std::string> standard_parameter_names() const;
};

/// Parameter names of one link in standard order without the joint index: XX XY XZ YY YZ ZZ MX MY
/// MZ M.
const std::vector<std::string>& link_parameter_labels();

/// Converts (mass m, centre of mass c in link frame, inertia I_C about the centre of mass with axes
/// of the link frame) into standard parameters about the link origin (parallel-axis theorem,
/// seed 1 eq. 24).
LinkParams link_params_from_com(double m, const Eigen::Vector3d& c, const Eigen::Matrix3d& I_C);

/// The 3×3 inertia about the link origin from standard parameters.
Eigen::Matrix3d inertia_about_origin(const LinkParams& p);

/// Expresses the standard parameters p of a body, given about the origin of frame B in frame B, in
/// a frame A where frame B has pose (R_AB, p_AB): returns the same body's parameters about A's
/// origin in A's axes. Identity: with r' = R_AB·r + p_AB for every mass element, h' = R_AB·h +
/// m·p_AB and I'_O = R_AB·I_O·R_ABᵀ + (2 p_ABᵀ(R_AB h))·1 − (p_AB (R_AB h)ᵀ + (R_AB h) p_ABᵀ) +
/// m(|p_AB|²·1 − p_AB p_ABᵀ) (seed 1 eq. 24 generalised; division-free, valid for m = 0). Used to
/// merge links across fixed joints (docs/methods/model.md).
LinkParams transform_link_params(const LinkParams& p, const Eigen::Matrix3d& R_AB,
                                 const Eigen::Vector3d& p_AB);

}  // namespace dynid
