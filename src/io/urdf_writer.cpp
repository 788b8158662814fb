#include "dynid/io/urdf_writer.hpp"

#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>

#include <Eigen/Geometry>

#include "dynid/common/error.hpp"
#include "dynid/io/atomic_file.hpp"
#include "dynid/io/markup.hpp"

namespace dynid {

namespace {

std::string vec3(const Eigen::Vector3d& v) {
  char buf[128];
  std::snprintf(buf, sizeof(buf), "%.17g %.17g %.17g", v.x(), v.y(), v.z());
  return buf;
}

// URDF rpy: R = Rz(yaw)·Ry(pitch)·Rx(roll).
Eigen::Vector3d rpy_from_rotation(const Eigen::Matrix3d& R) {
  const double pitch = std::atan2(-R(2, 0), std::hypot(R(0, 0), R(1, 0)));
  double roll, yaw;
  if (std::abs(std::cos(pitch)) > 1e-12) {
    roll = std::atan2(R(2, 1), R(2, 2));
    yaw = std::atan2(R(1, 0), R(0, 0));
  } else {  // gimbal lock: put everything in yaw
    roll = 0.0;
    yaw = std::atan2(-R(0, 1), R(1, 1));
  }
  return {roll, pitch, yaw};
}

std::string number(double x) {
  char buf[64];
  std::snprintf(buf, sizeof(buf), "%.17g", x);
  return buf;
}

}  // namespace

ComInertial com_inertial(const LinkParams& p) {
  ComInertial out;
  out.mass = p(9);
  if (out.mass > 0.0) out.com = p.segment<3>(6) / out.mass;
  const Eigen::Vector3d& c = out.com;
  out.inertia = inertia_about_origin(p) -
                out.mass * (c.squaredNorm() * Eigen::Matrix3d::Identity() - c * c.transpose());
  return out;
}

std::string to_urdf(const Model& model, const UrdfWriteOptions& options) {
  std::ostringstream out;
  out << "<?xml version=\"1.0\"?>\n<robot name=\""
      << markup_escaped(model.name.empty() ? "robot" : model.name) << "\">\n";
  if (options.mujoco_compiler_tag) {
    out << "  <mujoco><compiler discardvisual=\"true\" fusestatic=\"false\" "
           "balanceinertia=\"false\" angle=\"radian\"/></mujoco>\n";
  }
  out << "  <link name=\"" << markup_escaped(options.root_link) << "\"/>\n";
  auto link_name = [&](int j) {
    const Joint& joint = model.joints[j];
    return markup_escaped(joint.link_name.empty() ? joint.name + "_link" : joint.link_name);
  };
  for (int j = 0; j < model.dof(); ++j) {
    const LinkParams& p = model.links[j];
    const double m = p(9);
    out << "  <link name=\"" << link_name(j) << "\">\n";
    if (m > 0.0 || !p.head<6>().isZero(0.0)) {
      // A massless link can still carry rotational inertia (e.g. a rotor-only link 1).
      const ComInertial inertial = com_inertial(p);
      const Eigen::Vector3d& c = inertial.com;
      const Eigen::Matrix3d& I_C = inertial.inertia;
      out << "    <inertial>\n      <origin xyz=\"" << vec3(c) << "\" rpy=\"0 0 0\"/>\n"
          << "      <mass value=\"" << number(m) << "\"/>\n"
          << "      <inertia ixx=\"" << number(I_C(0, 0)) << "\" ixy=\"" << number(I_C(0, 1))
          << "\" ixz=\"" << number(I_C(0, 2)) << "\" iyy=\"" << number(I_C(1, 1)) << "\" iyz=\""
          << number(I_C(1, 2)) << "\" izz=\"" << number(I_C(2, 2)) << "\"/>\n    </inertial>\n";
    }
    out << "  </link>\n";
  }
  for (int j = 0; j < model.dof(); ++j) {
    const Joint& joint = model.joints[j];
    const bool prismatic = joint.type == JointType::kPrismatic;
    const bool bounded = std::isfinite(joint.limits.lower) && std::isfinite(joint.limits.upper);
    const char* type = prismatic ? "prismatic" : (bounded ? "revolute" : "continuous");
    out << "  <joint name=\"" << markup_escaped(joint.name) << "\" type=\"" << type << "\">\n"
        << "    <parent link=\""
        << (joint.parent < 0 ? markup_escaped(options.root_link) : link_name(joint.parent))
        << "\"/>\n    <child link=\"" << link_name(j) << "\"/>\n"
        << "    <origin xyz=\"" << vec3(joint.p_PJ) << "\" rpy=\""
        << vec3(rpy_from_rotation(joint.R_PJ)) << "\"/>\n    <axis xyz=\"" << vec3(joint.axis)
        << "\"/>\n";
    if (std::string(type) != "continuous" || std::isfinite(joint.limits.effort) ||
        std::isfinite(joint.limits.velocity)) {
      const auto finite_or = [](double v, double fallback) {
        return std::isfinite(v) ? v : fallback;
      };
      out << "    <limit lower=\"" << number(finite_or(joint.limits.lower, -1e3)) << "\" upper=\""
          << number(finite_or(joint.limits.upper, 1e3)) << "\" effort=\""
          << number(finite_or(joint.limits.effort, 1e6)) << "\" velocity=\""
          << number(finite_or(joint.limits.velocity, 1e6)) << "\"/>\n";
    }
    if (joint.friction.Fv != 0.0 || joint.friction.Fc != 0.0) {
      out << "    <dynamics damping=\"" << number(joint.friction.Fv) << "\" friction=\""
          << number(joint.friction.Fc) << "\"/>\n";
    }
    out << "  </joint>\n";
  }
  out << "</robot>\n";
  return out.str();
}

void write_urdf(const Model& model, const std::string& path, const UrdfWriteOptions& options) {
  write_text_atomic(path, to_urdf(model, options));
}

}  // namespace dynid
