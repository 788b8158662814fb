#include "dynid/model/mdh_loader.hpp"

#include <cmath>
#include <filesystem>
#include <limits>
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include <yaml-cpp/yaml.h>
#include <Eigen/Geometry>

#include "dynid/common/error.hpp"
#include "dynid/common/message.hpp"
#include "dynid/model/urdf_loader.hpp"

namespace dynid {

Joint mdh_joint(const MdhRow& row) {
  // Khalil & Kleinfinger (1986): T_{a(j),j} = RotX(α)·TransX(d)·RotZ(θ)·TransZ(r). RotZ and TransZ
  // commute, so the joint motion (θ += q or r += q) can be moved to the right end.
  Joint j;
  const Eigen::Matrix3d Rx =
      Eigen::AngleAxisd(row.alpha, Eigen::Vector3d::UnitX()).toRotationMatrix();
  j.R_PJ = Rx * Eigen::AngleAxisd(row.theta, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  j.p_PJ = Eigen::Vector3d(row.d, 0.0, 0.0) + Rx * Eigen::Vector3d(0.0, 0.0, row.r);
  j.axis = Eigen::Vector3d::UnitZ();
  j.type = row.sigma == 1 ? JointType::kPrismatic : JointType::kRevolute;
  return j;
}

namespace {

/// Context for one-line error messages: "<source>: <where>: <problem>; <fix>".
struct Ctx {
  std::string source;
  [[noreturn]] void fail(const std::string& where, const std::string& what) const {
    throw Error("robot file '" + source + "': " + (where.empty() ? "" : where + ": ") + what);
  }
};

/// Parses a YAML scalar as a number; also accepts multiples of pi such as "pi/2", "-pi", "2*pi/3".
bool parse_number(const std::string& s, double& out) {
  std::string t;
  for (char c : s) {
    if (c != ' ') t += c;
  }
  if (t.empty()) return false;
  // Plain numbers (yaml-cpp's .inf/.nan spellings included).
  if (t == ".nan" || t == ".NaN" || t == ".NAN") {
    out = std::numeric_limits<double>::quiet_NaN();
    return true;
  }
  if (t == ".inf" || t == "+.inf" || t == ".Inf" || t == "+.Inf" || t == ".INF" || t == "+.INF") {
    out = std::numeric_limits<double>::infinity();
    return true;
  }
  if (t == "-.inf" || t == "-.Inf" || t == "-.INF") {
    out = -std::numeric_limits<double>::infinity();
    return true;
  }
  {
    std::istringstream is(t);
    is.imbue(std::locale::classic());
    double v = 0.0;
    if ((is >> v) && is.peek() == std::char_traits<char>::eof()) {
      out = v;
      return true;
    }
  }
  const std::size_t pi = t.find("pi");
  if (pi == std::string::npos) return false;
  std::string pre = t.substr(0, pi);
  const std::string post = t.substr(pi + 2);
  double factor = 1.0;
  if (pre == "-") {
    factor = -1.0;
  } else if (pre == "+" || pre.empty()) {
    factor = 1.0;
  } else {
    if (pre.back() != '*') return false;
    pre.pop_back();
    std::istringstream is(pre);
    is.imbue(std::locale::classic());
    if (!(is >> factor) || is.peek() != std::char_traits<char>::eof()) return false;
  }
  double divisor = 1.0;
  if (!post.empty()) {
    if (post[0] != '/') return false;
    std::istringstream is(post.substr(1));
    is.imbue(std::locale::classic());
    if (!(is >> divisor) || is.peek() != std::char_traits<char>::eof() || divisor == 0.0) {
      return false;
    }
  }
  out = factor * M_PI / divisor;
  return true;
}

double as_number(const YAML::Node& node, const Ctx& ctx, const std::string& where) {
  if (!node.IsScalar()) ctx.fail(where, "must be a number; give a single finite value");
  double v = 0.0;
  if (!parse_number(node.Scalar(), v)) {
    ctx.fail(where, "'" + printable(node.Scalar(), 40) +
                        "' is not a number; give a finite value (or k*pi/m)");
  }
  if (!std::isfinite(v))
    ctx.fail(where, "is " + printable(node.Scalar(), 40) + "; give a finite value");
  return v;
}

bool has(const YAML::Node& map, const std::string& key) {
  return map[key].IsDefined();
}

double req(const YAML::Node& map, const std::string& key, const Ctx& ctx,
           const std::string& where) {
  const YAML::Node n = map[key];
  if (!n.IsDefined() || n.IsNull()) ctx.fail(where, "missing key '" + key + "'; add it");
  return as_number(n, ctx, where + "." + key);
}

double opt(const YAML::Node& map, const std::string& key, double fallback, const Ctx& ctx,
           const std::string& where) {
  const YAML::Node n = map[key];
  if (!n.IsDefined() || n.IsNull()) return fallback;
  return as_number(n, ctx, where + "." + key);
}

Eigen::VectorXd vec(const YAML::Node& n, int size, const Ctx& ctx, const std::string& where) {
  if (!n.IsSequence()) {
    ctx.fail(where, "must be a list of " + std::to_string(size) + " numbers");
  }
  if (size >= 0 && static_cast<int>(n.size()) != size) {
    ctx.fail(where,
             "has " + std::to_string(n.size()) + " values; give exactly " + std::to_string(size));
  }
  Eigen::VectorXd v(n.size());
  for (std::size_t i = 0; i < n.size(); ++i) {
    v[i] = as_number(n[i], ctx, where + "[" + std::to_string(i) + "]");
  }
  return v;
}

void check_keys(const YAML::Node& map, const std::set<std::string>& allowed, const Ctx& ctx,
                const std::string& where) {
  if (!map.IsMap()) ctx.fail(where, "must be a map of key: value pairs");
  for (const auto& kv : map) {
    const std::string key = kv.first.as<std::string>();
    if (!allowed.count(key)) {
      std::string list;
      for (const auto& a : allowed) list += (list.empty() ? "" : ", ") + a;
      ctx.fail(where, "unknown key '" + printable(key, 40) + "'; allowed keys are " + list);
    }
  }
}

Eigen::Matrix3d rpy_to_matrix(const Eigen::Vector3d& rpy) {
  // URDF convention: R = Rz(yaw)·Ry(pitch)·Rx(roll).
  return (Eigen::AngleAxisd(rpy.z(), Eigen::Vector3d::UnitZ()) *
          Eigen::AngleAxisd(rpy.y(), Eigen::Vector3d::UnitY()) *
          Eigen::AngleAxisd(rpy.x(), Eigen::Vector3d::UnitX()))
      .toRotationMatrix();
}

Eigen::Matrix3d sym6(const Eigen::VectorXd& v) {
  Eigen::Matrix3d I;
  I << v[0], v[1], v[2], v[1], v[3], v[4], v[2], v[4], v[5];
  return I;
}

JointFriction read_friction(const YAML::Node& map, JointFriction f, const Ctx& ctx,
                            const std::string& where) {
  f.Ia = opt(map, "Ia", f.Ia, ctx, where);
  f.Fv = opt(map, "Fv", f.Fv, ctx, where);
  f.Fc = opt(map, "Fc", f.Fc, ctx, where);
  f.Fo = opt(map, "Fo", f.Fo, ctx, where);
  if (f.Ia < 0.0 || f.Fv < 0.0 || f.Fc < 0.0) {
    ctx.fail(where, "Ia, Fv and Fc must be >= 0; fix their signs");
  }
  return f;
}

LinkParams read_inertia(const YAML::Node& row, const Ctx& ctx, const std::string& where) {
  const bool full = has(row, "inertia");
  const bool com_form = has(row, "mass") || has(row, "com") || has(row, "inertia_com");
  if (full && com_form) {
    ctx.fail(where, "give either 'inertia' or 'mass'+'com'+'inertia_com', not both");
  }
  if (full) {
    const LinkParams p = vec(row["inertia"], kLinkParams, ctx, where + ".inertia");
    if (p(9) < 0.0) ctx.fail(where + ".inertia", "has negative mass M; give a mass >= 0");
    return p;
  }
  if (!com_form) {
    ctx.fail(where,
             "missing key 'inertia' (or 'mass', 'com' and 'inertia_com'); add the link's "
             "inertial parameters");
  }
  const double m = req(row, "mass", ctx, where);
  if (m < 0.0) ctx.fail(where + ".mass", "is negative; give a mass >= 0");
  if (!has(row, "com")) ctx.fail(where, "missing key 'com'; add the centre of mass [x, y, z]");
  if (!has(row, "inertia_com")) {
    ctx.fail(where, "missing key 'inertia_com'; add [XX, XY, XZ, YY, YZ, ZZ] about the COM");
  }
  const Eigen::Vector3d c = vec(row["com"], 3, ctx, where + ".com");
  const Eigen::Matrix3d I_C = sym6(vec(row["inertia_com"], 6, ctx, where + ".inertia_com"));
  return link_params_from_com(m, c, I_C);  // seed 1 eq. 24
}

JointLimits read_limits(const YAML::Node& n, const Ctx& ctx, const std::string& where) {
  check_keys(n, {"lower", "upper", "velocity", "effort"}, ctx, where);
  JointLimits l;
  l.lower = opt(n, "lower", l.lower, ctx, where);
  l.upper = opt(n, "upper", l.upper, ctx, where);
  l.velocity = opt(n, "velocity", l.velocity, ctx, where);
  l.effort = opt(n, "effort", l.effort, ctx, where);
  if (!(l.lower <= l.upper)) ctx.fail(where, "lower is above upper; swap them");
  if (l.velocity <= 0.0 || l.effort <= 0.0) {
    ctx.fail(where, "velocity and effort limits must be > 0; omit them for no limit");
  }
  return l;
}

std::string row_where(int k, const YAML::Node& row) {
  std::string w = "joints[" + std::to_string(k + 1) + "]";
  if (row.IsMap() && row["name"].IsDefined() && row["name"].IsScalar()) {
    w += " ('" + printable(row["name"].Scalar(), 40) + "')";
  }
  return w;
}

void read_mdh_table(const YAML::Node& doc, const Ctx& ctx, Model& model) {
  const YAML::Node rows = doc["joints"];
  if (!rows.IsSequence() || rows.size() == 0) {
    ctx.fail("joints", "must be a non-empty list of MDH rows");
  }
  if (rows.size() > static_cast<std::size_t>(kMaxJoints)) {
    ctx.fail("joints", "has " + std::to_string(rows.size()) + " rows; dynid handles at most " +
                           std::to_string(kMaxJoints) +
                           " joints; split the model or make joints fixed");
  }
  std::map<std::string, std::size_t> row_of_name;
  Joint base_pose;  // R_PJ, p_PJ of the base placement
  if (has(doc, "base")) {
    const YAML::Node b = doc["base"];
    check_keys(b, {"xyz", "rpy"}, ctx, "base");
    if (has(b, "xyz")) base_pose.p_PJ = vec(b["xyz"], 3, ctx, "base.xyz");
    if (has(b, "rpy")) base_pose.R_PJ = rpy_to_matrix(vec(b["rpy"], 3, ctx, "base.rpy"));
  }
  const std::set<std::string> kk_keys = {
      "name",    "link", "sigma", "alpha",       "d",  "theta", "r",  "parent", "limits",
      "inertia", "mass", "com",   "inertia_com", "Ia", "Fv",    "Fc", "Fo"};
  const std::set<std::string> craig_keys = {
      "name",    "link", "sigma", "alpha_prev",  "a_prev", "theta", "d",  "parent", "limits",
      "inertia", "mass", "com",   "inertia_com", "Ia",     "Fv",    "Fc", "Fo"};
  for (std::size_t k = 0; k < rows.size(); ++k) {
    const YAML::Node row = rows[k];
    const std::string where = row_where(static_cast<int>(k), row);
    if (!row.IsMap()) ctx.fail(where, "must be a map with the MDH keys of one joint");
    const bool craig = has(row, "alpha_prev") || has(row, "a_prev");
    check_keys(row, craig ? craig_keys : kk_keys, ctx, where);
    MdhRow mdh;
    const double sigma = req(row, "sigma", ctx, where);
    if (sigma != 0.0 && sigma != 1.0) {
      ctx.fail(where + ".sigma", "must be 0 (revolute) or 1 (prismatic)");
    }
    mdh.sigma = static_cast<int>(sigma);
    if (craig) {  // Craig: alpha_{i-1}, a_{i-1}, theta_i, d_i
      mdh.alpha = req(row, "alpha_prev", ctx, where);
      mdh.d = req(row, "a_prev", ctx, where);
      mdh.theta = req(row, "theta", ctx, where);
      mdh.r = req(row, "d", ctx, where);
    } else {  // Khalil–Kleinfinger: alpha_j, d_j, theta_j, r_j
      mdh.alpha = req(row, "alpha", ctx, where);
      mdh.d = req(row, "d", ctx, where);
      mdh.theta = req(row, "theta", ctx, where);
      mdh.r = req(row, "r", ctx, where);
    }
    Joint j = mdh_joint(mdh);
    j.name = has(row, "name") ? row["name"].as<std::string>() : "joint" + std::to_string(k + 1);
    const auto [seen, fresh] = row_of_name.emplace(j.name, k);
    if (!fresh) {
      ctx.fail(where + ".name", "repeats the name of joints[" + std::to_string(seen->second + 1) +
                                    "]; give every joint a unique name");
    }
    j.link_name = has(row, "link") ? row["link"].as<std::string>() : "link" + std::to_string(k + 1);
    const double parent = opt(row, "parent", static_cast<double>(k), ctx, where);
    if (parent != std::floor(parent) || parent < 0.0 || parent > static_cast<double>(k)) {
      ctx.fail(where + ".parent", "must be 0 (base) or the 1-based index of an earlier row (1.." +
                                      std::to_string(k) + ")");
    }
    j.parent = static_cast<int>(parent) - 1;
    if (j.parent < 0) {
      j.p_PJ = base_pose.p_PJ + base_pose.R_PJ * j.p_PJ;
      j.R_PJ = base_pose.R_PJ * j.R_PJ;
    }
    if (has(row, "limits")) j.limits = read_limits(row["limits"], ctx, where + ".limits");
    j.friction = read_friction(row, JointFriction{}, ctx, where);
    model.links.push_back(read_inertia(row, ctx, where));
    model.joints.push_back(j);
  }
}

void read_transmission(const YAML::Node& doc, const Ctx& ctx, Model& model) {
  const int n = model.dof();
  const bool has_tr = has(doc, "transmission");
  const bool has_gr = has(doc, "gear_ratios");
  if (has_tr && has_gr) {
    ctx.fail("", "give either 'transmission' or 'gear_ratios', not both");
  }
  if (has_gr) {
    const Eigen::VectorXd g = vec(doc["gear_ratios"], n, ctx, "gear_ratios");
    model.transmission.N = g.asDiagonal();
    model.transmission.q_offset = Eigen::VectorXd::Zero(n);
  }
  if (has_tr) {
    const YAML::Node t = doc["transmission"];
    check_keys(t, {"N", "gear_ratios", "q_offset"}, ctx, "transmission");
    if (has(t, "N") == has(t, "gear_ratios")) {
      ctx.fail("transmission", "give exactly one of 'N' (n x n matrix) or 'gear_ratios'");
    }
    if (has(t, "N")) {
      const YAML::Node rows = t["N"];
      if (!rows.IsSequence() || static_cast<int>(rows.size()) != n) {
        ctx.fail("transmission.N", "must be a " + std::to_string(n) + "x" + std::to_string(n) +
                                       " matrix (list of rows) for the " + std::to_string(n) +
                                       " joints of the model");
      }
      model.transmission.N.resize(n, n);
      for (int i = 0; i < n; ++i) {
        model.transmission.N.row(i) =
            vec(rows[i], n, ctx, "transmission.N[" + std::to_string(i) + "]").transpose();
      }
    } else {
      const Eigen::VectorXd g = vec(t["gear_ratios"], n, ctx, "transmission.gear_ratios");
      model.transmission.N = g.asDiagonal();
    }
    model.transmission.q_offset = has(t, "q_offset")
                                      ? vec(t["q_offset"], n, ctx, "transmission.q_offset")
                                      : Eigen::VectorXd::Zero(n);
  }
}

}  // namespace

Model parse_yaml_model(const std::string& yaml, const std::string& source,
                       const std::string& base_dir, std::vector<std::string>* warnings) {
  const Ctx ctx{source};
  YAML::Node doc;
  try {
    doc = YAML::Load(yaml);
  } catch (const YAML::Exception& e) {
    throw Error("robot file '" + source + "', line " + std::to_string(e.mark.line + 1) +
                ", column " + std::to_string(e.mark.column + 1) + ": not valid YAML (" +
                printable(e.msg) + "); fix the syntax");
  }
  if (!doc.IsMap()) ctx.fail("", "the top level must be a map with 'joints:' or 'urdf:'");
  const bool mdh = has(doc, "joints");
  const bool urdf = has(doc, "urdf");
  if (mdh == urdf) ctx.fail("", "give exactly one of 'joints:' (MDH table) or 'urdf:' (file)");
  Model model;
  bool from_urdf = false;
  try {
    if (mdh) {
      check_keys(doc, {"name", "joints", "base", "gravity", "transmission", "gear_ratios"}, ctx,
                 "");
      read_mdh_table(doc, ctx, model);
      model.name = has(doc, "name") ? doc["name"].as<std::string>()
                                    : std::filesystem::path(source).stem().string();
    } else {
      check_keys(doc, {"name", "urdf", "gravity", "transmission", "gear_ratios", "friction"}, ctx,
                 "");
      std::filesystem::path p = doc["urdf"].as<std::string>();
      if (p.is_relative()) p = std::filesystem::path(base_dir) / p;
      // The URDF's links are checked (and tolerated faults said) once, here: the YAML's friction,
      // gravity and transmission change no link, so finalize() below does not say them again.
      model = load_urdf(p.string(), warnings);
      from_urdf = true;
      if (has(doc, "name")) model.name = doc["name"].as<std::string>();
      if (has(doc, "friction")) {
        const YAML::Node fr = doc["friction"];
        if (!fr.IsMap()) ctx.fail("friction", "must map joint names to {Ia, Fv, Fc, Fo}");
        for (const auto& kv : fr) {
          const std::string jname = kv.first.as<std::string>();
          const std::string where = "friction." + jname;
          int idx = -1;
          std::string names;
          for (int j = 0; j < model.dof(); ++j) {
            if (model.joints[j].name == jname) idx = j;
            names += (names.empty() ? "" : ", ") + model.joints[j].name;
          }
          if (idx < 0) ctx.fail(where, "no joint of that name; joints are " + names);
          check_keys(kv.second, {"Ia", "Fv", "Fc", "Fo"}, ctx, where);
          model.joints[idx].friction =
              read_friction(kv.second, model.joints[idx].friction, ctx, where);
        }
      }
    }
    if (has(doc, "gravity")) model.gravity = vec(doc["gravity"], 3, ctx, "gravity");
    read_transmission(doc, ctx, model);
  } catch (const YAML::Exception& e) {
    const std::string line =
        e.mark.is_null() ? std::string() : ", line " + std::to_string(e.mark.line + 1);
    // yaml-cpp's own words ("bad conversion") name neither the value nor the fix.
    const std::string reason = e.msg.find("bad conversion") != std::string::npos
                                   ? "a value has the wrong type (a list or map where a name or "
                                     "number belongs, or text where a number belongs)"
                                   : printable(e.msg);
    throw Error("robot file '" + source + "'" + line + ": " + reason + "; check the value's type");
  }
  model.source = source;
  std::vector<std::string> said_by_the_urdf;
  model.finalize(from_urdf ? &said_by_the_urdf : warnings);
  return model;
}

Model load_yaml_model(const std::string& path, std::vector<std::string>* warnings) {
  const std::string text = read_robot_file(path);
  return parse_yaml_model(text, path, std::filesystem::path(path).parent_path().string(), warnings);
}

}  // namespace dynid
