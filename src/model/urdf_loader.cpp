#include "dynid/model/urdf_loader.hpp"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <map>
#include <memory>
#include <optional>
#include <sstream>
#include <unordered_set>
#include <utility>
#include <vector>

#include <sys/stat.h>

#include <console_bridge/console.h>
#include <tinyxml2.h>
#include <urdf_parser/urdf_parser.h>
#include <Eigen/Geometry>

#include "dynid/common/error.hpp"
#include "dynid/common/input_file.hpp"
#include "dynid/common/message.hpp"

namespace dynid {

std::string read_robot_file(const std::string& path) {
  struct stat st {};
  if (::stat(path.c_str(), &st) == 0 && S_ISDIR(st.st_mode)) {
    throw Error("robot file '" + path + "' is a directory; give the path of a URDF or YAML file");
  }
  require_regular_file(path, "robot file");
  std::unique_ptr<std::FILE, int (*)(std::FILE*)> file(std::fopen(path.c_str(), "rb"),
                                                       &std::fclose);
  if (!file) {
    throw Error("cannot open robot file '" + path + "' (" + std::strerror(errno) +
                "); check the path and its permissions");
  }
  // Read with a cap instead of trusting a size: devices and pipes (/dev/zero) have none.
  std::string text;
  char buffer[1 << 16];
  std::size_t got = 0;
  while ((got = std::fread(buffer, 1, sizeof(buffer), file.get())) > 0) {
    if (text.size() + got > kMaxRobotFileBytes) {
      throw Error("robot file '" + path + "' is larger than " +
                  std::to_string(kMaxRobotFileBytes >> 20) +
                  " MiB, the limit for a robot description; check that it is the right file");
    }
    text.append(buffer, got);
  }
  if (std::ferror(file.get())) {
    throw Error("robot file '" + path + "': read error (" + std::strerror(errno) +
                "); check the file");
  }
  return text;
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
    throw Error("link '" + link.name + "' has negative mass " + short_number(in.mass) +
                " kg; give a mass >= 0 in its <inertial> block");
  }
  return link_params_from_com(in.mass, o.p, I_C);
}

/// True when `text` is `count` numbers separated by white space (strtod, the whole text).
bool numbers_in(const char* text, int count) {
  const char* p = text;
  for (int k = 0; k < count; ++k) {
    char* end = nullptr;
    const double x = std::strtod(p, &end);
    if (end == p || !std::isfinite(x)) return false;
    p = end;
  }
  while (*p == ' ' || *p == '\t' || *p == '\n' || *p == '\r') ++p;
  return *p == '\0';
}

/// urdfdom reads a number it cannot parse in <inertial> (a leftover xacro `${l}`) as 0 without a
/// word, so a link would load massless: every numeric attribute of every <inertial> is checked in
/// the raw XML first. Throws dynid::Error naming the link, the element and the attribute.
void check_inertial_numbers(const tinyxml2::XMLElement& robot, const std::string& source) {
  struct Numeric {
    const char* element;
    const char* attribute;
    int count;
  };
  static const Numeric kNumeric[] = {
      {"origin", "xyz", 3},  {"origin", "rpy", 3},  {"mass", "value", 1},
      {"inertia", "ixx", 1}, {"inertia", "ixy", 1}, {"inertia", "ixz", 1},
      {"inertia", "iyy", 1}, {"inertia", "iyz", 1}, {"inertia", "izz", 1}};
  for (const tinyxml2::XMLElement* link = robot.FirstChildElement("link"); link;
       link = link->NextSiblingElement("link")) {
    const tinyxml2::XMLElement* inertial = link->FirstChildElement("inertial");
    if (!inertial) continue;
    const char* name = link->Attribute("name");
    for (const Numeric& n : kNumeric) {
      const tinyxml2::XMLElement* e = inertial->FirstChildElement(n.element);
      const char* text = e ? e->Attribute(n.attribute) : nullptr;
      if (!text || numbers_in(text, n.count)) continue;
      const std::string value = printable(text);
      const bool xacro = value.find('$') != std::string::npos;
      throw Error(
          "link '" + printable(name ? name : "") + "' in '" + source + "': <inertial> <" +
          n.element + " " + n.attribute + "=\"" + value + "\"> is not " +
          (n.count == 1 ? "a number" : std::to_string(n.count) + " numbers") +
          (xacro ? " (a xacro expression left unexpanded: run xacro on the file first)" : "") +
          "; write the value as a number");
    }
  }
}

/// Joint names in the order of their <joint> elements in the file (urdfdom keeps its child_joints
/// in a std::map order, i.e. sorted by name, so the file order is read separately).
/// What the raw XML says before urdfdom reads it: the joints' file order (urdfdom keeps its
/// child_joints sorted by name) and, when a <limit> had to be completed, the text to parse.
struct RawUrdf {
  std::map<std::string, int> order;
  std::optional<std::string> completed;  ///< the XML with missing limit attributes set
};

/// Reads the XML with tinyxml2: checks the <inertial> numbers (check_inertial_numbers), records
/// the joint order, and completes a <limit> without effort or velocity (urdfdom refuses it,
/// "joint limit: no effort", and URDFs written back by other tools omit them): with `warnings`
/// the attribute is set to 0, which dynid reads as unlimited, and a warning names the joint;
/// without, it is an error naming the joint.
RawUrdf read_raw_urdf(const std::string& xml, const std::string& source,
                      std::vector<std::string>* warnings) {
  tinyxml2::XMLDocument doc;
  if (doc.Parse(xml.c_str(), xml.size()) != tinyxml2::XML_SUCCESS) {
    const std::string detail = printable(doc.ErrorStr() ? doc.ErrorStr() : "unknown error");
    throw Error("robot file '" + source + "' is not well-formed XML (" + detail +
                "); fix the XML syntax");
  }
  tinyxml2::XMLElement* robot = doc.FirstChildElement("robot");
  if (!robot) {
    throw Error("robot file '" + source + "' has no <robot> element; it must be a URDF file");
  }
  check_inertial_numbers(*robot, source);
  RawUrdf out;
  int k = 0;
  bool completed = false;
  for (tinyxml2::XMLElement* e = robot->FirstChildElement("joint"); e;
       e = e->NextSiblingElement("joint")) {
    const char* name = e->Attribute("name");
    if (name) out.order.emplace(name, k++);
    tinyxml2::XMLElement* limit = e->FirstChildElement("limit");
    if (!limit) continue;
    std::string missing;
    for (const char* attribute : {"effort", "velocity"}) {
      if (limit->Attribute(attribute)) continue;
      missing += (missing.empty() ? "" : " and ") + std::string(attribute);
      limit->SetAttribute(attribute, "0");
    }
    if (missing.empty()) continue;
    const std::string what = "joint '" + printable(name ? name : "") + "' in '" + source +
                             "' has a <limit> without " + missing;
    if (!warnings) {
      throw Error(what +
                  " (the URDF format requires both); add them (dynid reads such a joint "
                  "as unlimited unless --strict)");
    }
    warnings->push_back(what + "; read as unlimited (--strict refuses it)");
    completed = true;
  }
  if (completed) {
    tinyxml2::XMLPrinter printer;
    doc.Print(&printer);
    out.completed = std::string(printer.CStr());
  }
  return out;
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

/// Routes console_bridge (urdfdom's logging) into a buffer for the lifetime of the object, so that
/// urdfdom prints nothing and its first error can become part of dynid's one-line message.
class ConsoleCapture : public console_bridge::OutputHandler {
 public:
  ConsoleCapture() { console_bridge::useOutputHandler(this); }
  ~ConsoleCapture() override { console_bridge::restorePreviousOutputHandler(); }
  ConsoleCapture(const ConsoleCapture&) = delete;
  ConsoleCapture& operator=(const ConsoleCapture&) = delete;

  void log(const std::string& text, console_bridge::LogLevel level, const char*, int) override {
    if (level >= console_bridge::CONSOLE_BRIDGE_LOG_ERROR && first_error_.empty())
      first_error_ = text;
  }
  const std::string& first_error() const { return first_error_; }

 private:
  std::string first_error_;
};

class TreeBuilder {
 public:
  TreeBuilder(const urdf::ModelInterface& urdf, const std::map<std::string, int>& order,
              std::string source)
      : urdf_(urdf), order_(order), source_(std::move(source)) {}

  /// Depth-first (pre-order) walk from `root` with an explicit stack, so the depth of the tree
  /// is not limited by the call stack; a link reached twice (a joint whose child is its own
  /// parent, or a cycle below the root) is an error. Each stack entry is a joint still to be
  /// visited, with the index of the nearest moving ancestor of its parent link (-1 for the base)
  /// and the pose of the parent link's frame in that ancestor's frame.
  void build(const urdf::Link& root) {
    struct Pending {
      urdf::JointSharedPtr joint;
      int moving_parent;
      Pose X;
    };
    std::vector<Pending> stack;
    std::unordered_set<std::string> seen{root.name};
    push_children(root, -1, Pose{}, stack);
    while (!stack.empty()) {
      const Pending top = std::move(stack.back());
      stack.pop_back();
      const urdf::Joint& uj = *top.joint;
      const urdf::LinkConstSharedPtr child = urdf_.getLink(uj.child_link_name);
      if (!child) {
        throw Error("joint '" + uj.name + "' in '" + source_ + "' names a missing child link '" +
                    uj.child_link_name + "'; add that <link>");
      }
      if (!seen.insert(child->name).second) {
        throw Error("joint '" + uj.name + "' in '" + source_ + "' leads back to link '" +
                    child->name +
                    "', which is already in the tree (a cycle); a URDF must be a tree: give every "
                    "link one parent joint and no joint its own parent as child");
      }
      const Pose X_child = top.X * to_pose(uj.parent_to_joint_origin_transform);
      switch (uj.type) {
        case urdf::Joint::FIXED: {
          if (top.moving_parent >= 0) {
            // Merge: the child's parameters, expressed about the moving ancestor's origin.
            model_.links[top.moving_parent] +=
                transform_link_params(urdf_link_params(*child), X_child.R, X_child.p);
          }
          push_children(*child, top.moving_parent, X_child, stack);
          break;
        }
        case urdf::Joint::REVOLUTE:
        case urdf::Joint::CONTINUOUS:
        case urdf::Joint::PRISMATIC: {
          if (uj.mimic) {
            // A mimic joint moves with another one: not a degree of freedom of its own, and
            // taken as free it would get parameters and torque columns no data can hold.
            throw Error("joint '" + uj.name + "' in '" + source_ + "' mimics joint '" +
                        uj.mimic->joint_name +
                        "' (a coupled joint, not supported): every moving joint of dynid is "
                        "independently actuated; make '" +
                        uj.name + "' fixed, or remove its <mimic> if it has its own actuator");
          }
          if (model_.dof() >= kMaxJoints) {
            throw Error("robot file '" + source_ + "' has more than " + std::to_string(kMaxJoints) +
                        " moving joints, the limit of dynid; split the model or make joints fixed");
          }
          model_.joints.push_back(moving_joint(uj, *child, top.moving_parent, X_child));
          model_.links.push_back(urdf_link_params(*child));
          push_children(*child, model_.dof() - 1, Pose{}, stack);
          break;
        }
        default:
          throw Error("joint '" + uj.name + "' in '" + source_ + "' has unsupported type '" +
                      type_name(uj.type) +
                      "'; supported types are revolute, continuous, prismatic and fixed");
      }
    }
  }

  Model& model() { return model_; }

 private:
  // Pushes the child joints of `link` so that they pop in file order.
  template <typename Stack>
  void push_children(const urdf::Link& link, int moving_parent, const Pose& X, Stack& stack) const {
    std::vector<urdf::JointSharedPtr> children = link.child_joints;
    std::stable_sort(children.begin(), children.end(),
                     [this](const urdf::JointSharedPtr& a, const urdf::JointSharedPtr& b) {
                       return rank(a->name) < rank(b->name);
                     });
    for (auto it = children.rbegin(); it != children.rend(); ++it)
      stack.push_back({*it, moving_parent, X});
  }

  Joint moving_joint(const urdf::Joint& uj, const urdf::Link& child, int moving_parent,
                     const Pose& X_child) const {
    Joint j;
    j.name = uj.name;
    j.link_name = child.name;
    j.type = uj.type == urdf::Joint::PRISMATIC ? JointType::kPrismatic : JointType::kRevolute;
    j.parent = moving_parent;
    j.R_PJ = X_child.R;
    j.p_PJ = X_child.p;
    j.axis = Eigen::Vector3d(uj.axis.x, uj.axis.y, uj.axis.z);
    if (uj.limits) {
      if (uj.type != urdf::Joint::CONTINUOUS) {
        j.limits.lower = uj.limits->lower;
        j.limits.upper = uj.limits->upper;
      }
      j.limits.velocity = uj.limits->velocity > 0.0 ? uj.limits->velocity : kInf;
      j.limits.effort = uj.limits->effort > 0.0 ? uj.limits->effort : kInf;
    }
    if (uj.dynamics) {
      j.friction.Fv = uj.dynamics->damping;
      j.friction.Fc = uj.dynamics->friction;
    }
    if (!std::isfinite(j.friction.Fv) || !std::isfinite(j.friction.Fc) || j.friction.Fv < 0.0 ||
        j.friction.Fc < 0.0) {
      throw Error("joint '" + uj.name + "' in '" + source_ +
                  "' has a negative or non-finite <dynamics damping/friction>; give values >= 0");
    }
    return j;
  }

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

Model parse_urdf(const std::string& xml, const std::string& source,
                 std::vector<std::string>* warnings) {
  const RawUrdf raw = read_raw_urdf(xml, source, warnings);
  const std::map<std::string, int>& order = raw.order;
  urdf::ModelInterfaceSharedPtr urdf;
  std::string urdfdom_message;
  {
    const ConsoleCapture capture;  // urdfdom reports through console_bridge: keep it off stderr
    urdf = urdf::parseURDF(raw.completed ? *raw.completed : xml);
    urdfdom_message = capture.first_error();
  }
  if (!urdf) {
    throw Error("robot file '" + source + "' is not a valid URDF (" +
                (urdfdom_message.empty() ? std::string("rejected by urdfdom")
                                         : printable(urdfdom_message)) +
                "); fix the file");
  }
  const urdf::LinkConstSharedPtr root = urdf->getRoot();
  if (!root) throw Error("robot file '" + source + "' has no root link; add a <link>");
  TreeBuilder builder(*urdf, order, source);
  builder.build(*root);
  Model model = std::move(builder.model());
  model.name = urdf->getName();
  model.source = source;
  if (model.dof() == 0) {
    throw Error("robot file '" + source +
                "' has no revolute, continuous or prismatic joint; add a moving joint");
  }
  model.finalize(warnings);
  return model;
}

Model load_urdf(const std::string& path, std::vector<std::string>* warnings) {
  Model model = parse_urdf(read_robot_file(path), path, warnings);
  model.urdf = path;
  return model;
}

}  // namespace dynid
