#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "dynid/model/model.hpp"

namespace dynid {

/// Reads a URDF file and builds a finalized Model (see parse_urdf for the mapping).
/// Throws dynid::Error "cannot open robot file '<path>'" when the file cannot be read, and every
/// error of parse_urdf. Model::urdf is `path`.
Model load_urdf(const std::string& path, std::vector<std::string>* warnings = nullptr);

/// Builds a finalized Model from URDF text; `source` names the text in error messages and is stored
/// in Model::source. Mapping (docs/methods/model.md, "URDF"):
/// - link frame j = frame of the URDF joint whose child is link j; R_PJ/p_PJ = the joint <origin>
///   composed with every fixed joint between the moving parent and this joint; axis = <axis> (in
///   frame j). Joint order: depth-first from the root link, children in the order their <joint>
///   elements appear in the file.
/// - revolute, continuous (position limits ±inf) and prismatic joints become Joints; fixed joints
///   are merged: the child's inertia is added to the moving ancestor link (transform_link_params)
///   and the grandchildren are re-parented with the composed transform. Mass fixed to the world
///   (the root link and everything fixed to it) does not move and is dropped.
/// - <inertial> with origin xyz/rpy: I = R·I_in·Rᵀ, then the parallel-axis theorem
///   (link_params_from_com, seed 1 eq. 24). <dynamics damping friction> -> Fv, Fc.
/// - <limit lower upper velocity effort>; a velocity or effort of 0 (unset) means unlimited.
/// Throws dynid::Error for malformed XML, an <inertial> value that is not a number (a leftover
/// xacro `${l}`, which urdfdom would read as 0; the message names the link), unsupported joint
/// types (floating, planar), a robot with no moving joint, and every check of Model::finalize. A
/// non-physical inertia is an error when `warnings` is null, else a line appended to it
/// (Model::finalize); so is a <limit> without effort or velocity (which URDFs written back by
/// other tools omit and urdfdom refuses), read as unlimited when tolerated.
Model parse_urdf(const std::string& xml, const std::string& source,
                 std::vector<std::string>* warnings = nullptr);

/// Largest robot description file (URDF or YAML) read_robot_file accepts [bytes]; docs/cli.md.
inline constexpr std::size_t kMaxRobotFileBytes = std::size_t{64} << 20;

/// Reads a whole text file, at most kMaxRobotFileBytes (read with a cap, so devices and pipes such
/// as /dev/zero end in an error, not in exhausted memory). Throws dynid::Error "cannot open robot
/// file '<path>'; ..." on failure, for a directory and for a file above the limit.
std::string read_robot_file(const std::string& path);

}  // namespace dynid
