#include "dynid/sim/load_sensor.hpp"

#include <cmath>
#include <random>
#include <set>
#include <string>

#include <yaml-cpp/yaml.h>

#include "dynid/common/error.hpp"
#include "dynid/common/input_file.hpp"
#include "dynid/common/message.hpp"
#include "dynid/dynamics/rnea.hpp"
#include "dynid/dynamics/workspace.hpp"

namespace dynid {
namespace {

// The load in link order (XX XY XZ YY YZ ZZ MX MY MZ M) from load order (m mcx … Izz).
LinkParams to_link_order(const Eigen::VectorXd& phi) {
  LinkParams p;
  p << phi(4), phi(5), phi(6), phi(7), phi(8), phi(9), phi(1), phi(2), phi(3), phi(0);
  return p;
}

void check_load(const Model& robot, const MountedLoad& load) {
  if (load.mount.link < 0 || load.mount.link >= robot.dof()) {
    throw Error("the load's link index " + std::to_string(load.mount.link) + " is outside 0.." +
                std::to_string(robot.dof() - 1) + "; name a link of '" + robot.name + "'");
  }
  if (load.phi.size() != 10 || !load.phi.allFinite()) {
    throw Error("the load needs 10 finite parameters m mcx mcy mcz Ixx Ixy Ixz Iyy Iyz Izz");
  }
}

std::vector<double> read_list(const YAML::Node& doc, const char* key, std::size_t count,
                              const std::string& path) {
  const YAML::Node node = doc[key];
  if (!node) {
    throw Error("load file " + path + " has no '" + key +
                "'; give mass, com [x, y, z] and inertia_com [Ixx, Ixy, Ixz, Iyy, Iyz, Izz]");
  }
  std::vector<double> v;
  if (count == 1 && node.IsScalar()) {
    v.push_back(node.as<double>());
  } else if (node.IsSequence() && node.size() == count) {
    for (const auto& x : node) v.push_back(x.as<double>());
  } else {
    throw Error("load file " + path + ": '" + key + "' must be " +
                (count == 1 ? std::string("one number")
                            : "a list of " + std::to_string(count) + " numbers"));
  }
  for (const double x : v) {
    if (!std::isfinite(x))
      throw Error("load file " + path + ": '" + key + "' has a value that is not finite");
  }
  return v;
}

}  // namespace

Eigen::VectorXd read_load_file(const std::string& path) {
  require_regular_file(path, "load file");
  YAML::Node doc;
  try {
    doc = YAML::LoadFile(path);
  } catch (const YAML::BadFile&) {
    throw Error("cannot read load file " + path + ": check the path");
  } catch (const YAML::Exception& e) {
    throw Error("load file " + path + " is not valid YAML (line " +
                std::to_string(e.mark.line + 1) + "): " + one_line(e.msg));
  }
  if (!doc.IsMap()) {
    throw Error("load file " + path +
                " must be a mapping: mass, com [x, y, z], inertia_com [Ixx, Ixy, Ixz, Iyy, Iyz, "
                "Izz] (sensor frame)");
  }
  static const std::set<std::string> kKnown = {"mass", "com", "inertia_com", "name"};
  for (const auto& entry : doc) {
    const std::string key = entry.first.as<std::string>();
    if (!kKnown.count(key)) {
      throw Error("load file " + path + ": unknown key '" + one_line(key) +
                  "'; the keys are mass, com, inertia_com (and an optional name)");
    }
  }
  double m = 0.0;
  std::vector<double> c, I;
  try {
    m = read_list(doc, "mass", 1, path)[0];
    c = read_list(doc, "com", 3, path);
    I = read_list(doc, "inertia_com", 6, path);
  } catch (const YAML::Exception&) {
    throw Error("load file " + path + ": mass, com and inertia_com must be numbers");
  }
  if (!(m > 0.0)) {
    throw Error("load file " + path + ": mass " + short_number(m) +
                " kg must be > 0 (a load of zero mass exerts no wrench); give the load's mass");
  }
  Eigen::Matrix3d I_C;
  I_C << I[0], I[1], I[2], I[1], I[3], I[4], I[2], I[4], I[5];
  const Eigen::Vector3d com(c[0], c[1], c[2]);
  const LinkParams p = link_params_from_com(m, com, I_C);
  Eigen::VectorXd phi(10);
  phi << p(9), p(6), p(7), p(8), p(0), p(1), p(2), p(3), p(4), p(5);
  const LoadPhysics physics = load_physics(phi, true);
  if (!physics.consistent) {
    throw Error("load file " + path + " is not a rigid body: " + one_line(physics.violated) +
                "; check inertia_com (about the centre of mass, sensor axes, kg m^2)");
  }
  return phi;
}

Model model_with_load(const Model& robot, const MountedLoad& load) {
  check_load(robot, load);
  Model out = robot;
  out.links[load.mount.link] +=
      transform_link_params(to_link_order(load.phi), load.mount.R_LS, load.mount.p_LS);
  return out;
}

Eigen::MatrixXd load_sensor_wrench(const Model& robot, const MountedLoad& load,
                                   const Eigen::Ref<const Eigen::MatrixXd>& q,
                                   const Eigen::Ref<const Eigen::MatrixXd>& dq,
                                   const Eigen::Ref<const Eigen::MatrixXd>& ddq) {
  check_load(robot, load);
  const int n = robot.dof();
  const Eigen::Index m = q.rows();
  if (q.cols() != n || dq.rows() != m || dq.cols() != n || ddq.rows() != m || ddq.cols() != n) {
    throw Error("the sensor wrench needs q, dq and ddq of " + std::to_string(n) +
                " columns and one row per sample each");
  }
  // The load as one more link whose joint frame is the sensor frame, held at zero: the backward
  // pass then yields the wrench the sensor exerts on the load (its joint transmits all six).
  Model carried = robot;
  carried.transmission = Transmission{};
  Joint holder;
  holder.name = "dynid_sensor";
  holder.link_name = "dynid_load";
  holder.parent = load.mount.link;
  holder.R_PJ = load.mount.R_LS;
  holder.p_PJ = load.mount.p_LS;
  carried.joints.push_back(holder);
  carried.links.push_back(to_link_order(load.phi));
  carried.finalize();
  Workspace ws(carried);
  Eigen::VectorXd q_all = Eigen::VectorXd::Zero(n + 1), dq_all = q_all, ddq_all = q_all;
  Eigen::VectorXd tau(n + 1);
  RneaOptions options;
  options.joint_terms = false;
  Eigen::MatrixXd wrench(m, 6);
  for (Eigen::Index k = 0; k < m; ++k) {
    q_all.head(n) = q.row(k).transpose();
    dq_all.head(n) = dq.row(k).transpose();
    ddq_all.head(n) = ddq.row(k).transpose();
    rnea(carried, ws, q_all, dq_all, ddq_all, tau, options);
    wrench.row(k).head<3>() = -ws.links[n].f.transpose();
    wrench.row(k).tail<3>() = -ws.links[n].n.transpose();
  }
  return wrench;
}

void add_wrench_noise(Eigen::MatrixXd& wrench, double force_std, double moment_std, unsigned seed) {
  if (!(force_std >= 0.0) || !(moment_std >= 0.0) || !std::isfinite(force_std) ||
      !std::isfinite(moment_std)) {
    throw Error("the wrench noise std must be finite and >= 0 (got " + short_number(force_std) +
                " N, " + short_number(moment_std) + " N m)");
  }
  if (wrench.cols() != 6) throw Error("the wrench needs 6 columns fx fy fz mx my mz");
  std::mt19937 rng(seed);
  std::normal_distribution<double> unit(0.0, 1.0);
  for (Eigen::Index k = 0; k < wrench.rows(); ++k) {
    for (int c = 0; c < 6; ++c) wrench(k, c) += (c < 3 ? force_std : moment_std) * unit(rng);
  }
}

}  // namespace dynid
