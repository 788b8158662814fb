#include "dynid/model/urdf_loader.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <limits>
#include <map>
#include <sstream>
#include <utility>
#include <vector>

#include <tinyxml2.h>
#include <urdf_parser/urdf_parser.h>
#include <Eigen/Geometry>

#include "dynid/common/error.hpp"

namespace dynid {

std::string read_robot_file(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) {
    throw Error("cannot open robot file '" + path + "'; check the path and its permissions");
  }
  std::ostringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

struct Pose {
  Eigen::Matrix3d R = Eigen::Matrix3d::Identity();
  Eigen::Vector3d p = Eigen::Vector3d::Zero();
  Pose operator*(const Pose& b) const { return {R * b.R, p + R * b.p}; }
};

Pose to_pose(const urdf::Pose& u) {
  Pose out;
  out.R = Eigen::Quaterniond(u.rotation.w, u.rotation.x, u.rotation.y, u.rotation.z)
              .normalized()
              .toRotationMatrix();
  out.p = Eigen::Vector3d(u.position.x, u.position.y, u.position.z);
  return out;
}

/// Standard parameters of a URDF link about its own frame origin: the <inertial> tensor is given
/// about the COM in the axes of the inertial origin, so I_C = R·I_in·Rᵀ (rotated into the link
/// frame) and then the parallel-axis theorem (seed 1 eq. 24) moves it to the link origin.
LinkParams urdf_link_params(const urdf::Link& link) {
  if (!link.inertial) return LinkParams::Zero();
  const urdf::Inertial& in = *link.inertial;
  const Pose o = to_pose(in.origin);
  Eigen::Matrix3d I_in;
  I_in << in.ixx, in.ixy, in.ixz, in.ixy, in.iyy, in.iyz, in.ixz, in.iyz, in.izz;
  const Eigen::Matrix3d I_C = o.R * I_in * o.R.transpose();
  if (!(in.mass >= 0.0)) {
    throw Error("link '" + link.name + "' has negative mass " + std::to_string(in.mass) +
                " kg; give a mass >= 0 in its <inertial> block");
  }
  return link_params_from_com(in.mass, o.p, I_C);
}

/// Joint names in the order of their <joint> elements in the file (urdfdom keeps its child_joints
/// in a std::map order, i.e. sorted by name, so the file order is read separately).
std::map<std::string, int> joint_file_order(const std::string& xml, const std::string& source) {
  tinyxml2::XMLDocument doc;
  if (doc.Parse(xml.c_str(), xml.size()) != tinyxml2::XML_SUCCESS) {
    std::string detail = doc.ErrorStr() ? doc.ErrorStr() : "unknown error";
    throw Error("robot file '" + source + "' is not well-formed XML (" + detail +
                "); fix the XML syntax");
  }
  const tinyxml2::XMLElement* robot = doc.FirstChildElement("robot");
  if (!robot) {
    throw Error("robot file '" + source + "' has no <robot> element; it must be a URDF file");
  }
  std::map<std::string, int> order;
  int k = 0;
  for (const tinyxml2::XMLElement* e = robot->FirstChildElement("joint"); e;
       e = e->NextSiblingElement("joint")) {
    const char* name = e->Attribute("name");
    if (name) order.emplace(name, k++);
  }
  return order;
}

const char* type_name(int type) {
  switch (type) {
    case urdf::Joint::FLOATING:
      return "floating";
    case urdf::Joint::PLANAR:
      return "planar";
    default:
      return "unknown";
  }
}

class TreeBuilder {
 public:
  TreeBuilder(const urdf::ModelInterface& urdf, const std::map<std::string, int>& order,
              std::string source)
      : urdf_(urdf), order_(order), source_(std::move(source)) {}

  /// Depth-first visit of `link`: `moving_parent` is the index of the nearest moving ancestor (-1
  /// for the base), `X` is the pose of `link`'s frame in that ancestor's frame.
  void visit(const urdf::Link& link, int moving_parent, const Pose& X) {
    std::vector<urdf::JointSharedPtr> children = link.child_joints;
    std::stable_sort(children.begin(), children.end(),
                     [this](const urdf::JointSharedPtr& a, const urdf::JointSharedPtr& b) {
                       return rank(a->name) < rank(b->name);
                     });
    for (const auto& uj : children) {
      const urdf::LinkConstSharedPtr child = urdf_.getLink(uj->child_link_name);
      if (!child) {
        throw Error("joint '" + uj->name + "' in '" + source_ + "' names a missing child link '" +
                    uj->child_link_name + "'; add that <link>");
      }
      const Pose X_child = X * to_pose(uj->parent_to_joint_origin_transform);
      switch (uj->type) {
        case urdf::Joint::FIXED: {
          if (moving_parent >= 0) {
            // Merge: the child's parameters, expressed about the moving ancestor's origin.
            model_.links[moving_parent] +=
                transform_link_params(urdf_link_params(*child), X_child.R, X_child.p);
          }
          visit(*child, moving_parent, X_child);
          break;
        }
        case urdf::Joint::REVOLUTE:
        case urdf::Joint::CONTINUOUS:
        case urdf::Joint::PRISMATIC: {
          Joint j;
          j.name = uj->name;
          j.link_name = child->name;
          j.type =
              uj->type == urdf::Joint::PRISMATIC ? JointType::kPrismatic : JointType::kRevolute;
          j.parent = moving_parent;
          j.R_PJ = X_child.R;
          j.p_PJ = X_child.p;
          j.axis = Eigen::Vector3d(uj->axis.x, uj->axis.y, uj->axis.z);
          if (uj->limits) {
            if (uj->type != urdf::Joint::CONTINUOUS) {
              j.limits.lower = uj->limits->lower;
              j.limits.upper = uj->limits->upper;
            }
            j.limits.velocity = uj->limits->velocity > 0.0 ? uj->limits->velocity : kInf;
            j.limits.effort = uj->limits->effort > 0.0 ? uj->limits->effort : kInf;
          }
          if (uj->dynamics) {
            j.friction.Fv = uj->dynamics->damping;
            j.friction.Fc = uj->dynamics->friction;
          }
          if (!std::isfinite(j.friction.Fv) || !std::isfinite(j.friction.Fc) ||
              j.friction.Fv < 0.0 || j.friction.Fc < 0.0) {
            throw Error("joint '" + uj->name + "' in '" + source_ +
                        "' has a negative or non-finite <dynamics damping/friction>; give values "
                        ">= 0");
          }
          model_.joints.push_back(j);
          model_.links.push_back(urdf_link_params(*child));
          visit(*child, static_cast<int>(model_.joints.size()) - 1, Pose{});
          break;
        }
        default:
          throw Error("joint '" + uj->name + "' in '" + source_ + "' has unsupported type '" +
                      type_name(uj->type) +
                      "'; supported types are revolute, continuous, prismatic and fixed");
      }
    }
  }

  Model& model() { return model_; }

 private:
  int rank(const std::string& name) const {
    const auto it = order_.find(name);
    return it == order_.end() ? std::numeric_limits<int>::max() : it->second;
  }

  const urdf::ModelInterface& urdf_;
  const std::map<std::string, int>& order_;
  std::string source_;
  Model model_;
};

}  // namespace

Model parse_urdf(const std::string& xml, const std::string& source) {
  const std::map<std::string, int> order = joint_file_order(xml, source);
  const urdf::ModelInterfaceSharedPtr urdf = urdf::parseURDF(xml);
  if (!urdf) {
    throw Error("robot file '" + source +
                "' is not a valid URDF (urdfdom rejected it; its message is printed above); fix "
                "the file");
  }
  const urdf::LinkConstSharedPtr root = urdf->getRoot();
  if (!root) throw Error("robot file '" + source + "' has no root link; add a <link>");
  TreeBuilder builder(*urdf, order, source);
  builder.visit(*root, -1, Pose{});
  Model model = std::move(builder.model());
  model.name = urdf->getName();
  model.source = source;
  if (model.dof() == 0) {
    throw Error("robot file '" + source +
                "' has no revolute, continuous or prismatic joint; add a moving joint");
  }
  model.finalize();
  return model;
}

Model load_urdf(const std::string& path) {
  return parse_urdf(read_robot_file(path), path);
}

}  // namespace dynid
