// Compiled without -march=native, symbols hidden except the bridge's own
// (cmake/DynidKdlBridge.cmake): every Eigen object here is made and freed by the same Eigen
// configuration as Debian's KDL.
#include "oracle/kdl_bridge.hpp"

#include <map>
#include <stdexcept>

#include <kdl/chaindynparam.hpp>
#include <kdl/chainfdsolver_recursive_newton_euler.hpp>
#include <kdl/chainidsolver_recursive_newton_euler.hpp>
#include <kdl/tree.hpp>
#include <kdl/treeidsolver_recursive_newton_euler.hpp>
#include <kdl_parser/kdl_parser.hpp>

namespace dynid::kdl {
namespace {

KDL::Tree parse(const std::string& urdf, UrdfSource source) {
  KDL::Tree tree;
  const bool ok = source == UrdfSource::kFile ? kdl_parser::treeFromFile(urdf, tree)
                                              : kdl_parser::treeFromString(urdf, tree);
  if (!ok) {
    throw std::runtime_error("kdl_parser could not read the URDF" +
                             (source == UrdfSource::kFile ? " " + urdf : std::string()));
  }
  return tree;
}

}  // namespace

struct Tree::Impl {
  KDL::Tree tree;               // before the solver, which keeps a reference to it
  std::vector<unsigned> index;  // KDL's q_nr of the caller's joint j
  KDL::TreeIdSolver_RNE solver;
  KDL::JntArray q, dq, ddq, tau;

  Impl(KDL::Tree parsed, const std::vector<std::string>& names, const double* g)
      : tree(std::move(parsed)),
        index(indices(tree, names)),
        solver(tree, KDL::Vector(g[0], g[1], g[2])),
        q(tree.getNrOfJoints()),
        dq(tree.getNrOfJoints()),
        ddq(tree.getNrOfJoints()),
        tau(tree.getNrOfJoints()) {}

  // Each KDL tree joint (q_nr) matched to the caller's order by joint name.
  static std::vector<unsigned> indices(const KDL::Tree& tree,
                                       const std::vector<std::string>& names) {
    std::map<std::string, unsigned> by_name;
    for (const auto& [name, element] : tree.getSegments()) {
      const KDL::Joint& joint = element.segment.getJoint();
      if (joint.getType() != KDL::Joint::None)
        by_name[joint.getName()] = GetTreeElementQNr(element);
    }
    std::vector<unsigned> out;
    for (const std::string& name : names) {
      const auto it = by_name.find(name);
      if (it == by_name.end()) throw std::runtime_error("KDL tree has no joint " + name);
      out.push_back(it->second);
    }
    return out;
  }
};

Tree::Tree(const std::string& urdf, UrdfSource source, const std::vector<std::string>& joint_names,
           const double* gravity)
    : impl_(std::make_unique<Impl>(parse(urdf, source), joint_names, gravity)) {}

Tree::~Tree() = default;

int Tree::joint_count() const {
  return static_cast<int>(impl_->tree.getNrOfJoints());
}

int Tree::inverse_dynamics(const double* q, const double* dq, const double* ddq, double* tau) {
  Impl& s = *impl_;
  const size_t n = s.index.size();
  for (size_t j = 0; j < n; ++j) {
    s.q(s.index[j]) = q[j];
    s.dq(s.index[j]) = dq[j];
    s.ddq(s.index[j]) = ddq[j];
  }
  const int status = s.solver.CartToJnt(s.q, s.dq, s.ddq, KDL::WrenchMap(), s.tau);
  for (size_t j = 0; j < n; ++j) tau[j] = s.tau(s.index[j]);
  return status;
}

struct Chain::Impl {
  KDL::Chain chain;  // before the solvers, which keep a reference to it
  KDL::ChainIdSolver_RNE id;
  KDL::ChainDynParam dyn;
  KDL::ChainFdSolver_RNE fd;
  KDL::JntArray q, dq, ddq, tau;
  KDL::JntSpaceInertiaMatrix mass;
  KDL::Wrenches f_ext;

  Impl(KDL::Chain c, const double* g)
      : chain(std::move(c)),
        id(chain, KDL::Vector(g[0], g[1], g[2])),
        dyn(chain, KDL::Vector(g[0], g[1], g[2])),
        fd(chain, KDL::Vector(g[0], g[1], g[2])),
        q(chain.getNrOfJoints()),
        dq(chain.getNrOfJoints()),
        ddq(chain.getNrOfJoints()),
        tau(chain.getNrOfJoints()),
        mass(chain.getNrOfJoints()),
        f_ext(chain.getNrOfSegments(), KDL::Wrench::Zero()) {}
};

namespace {

KDL::Chain chain_of(const std::string& urdf, UrdfSource source, const std::string& base_link,
                    const std::string& tip_link) {
  const KDL::Tree tree = parse(urdf, source);
  KDL::Chain chain;
  const std::string base = base_link.empty() ? tree.getRootSegment()->first : base_link;
  if (!tree.getChain(base, tip_link, chain)) {
    throw std::runtime_error("KDL tree has no chain from " + base + " to " + tip_link);
  }
  return chain;
}

void copy_in(const double* from, KDL::JntArray& to) {
  for (unsigned j = 0; j < to.rows(); ++j) to(j) = from[j];
}

void copy_out(const KDL::JntArray& from, double* to) {
  for (unsigned j = 0; j < from.rows(); ++j) to[j] = from(j);
}

}  // namespace

Chain::Chain(const std::string& urdf, UrdfSource source, const std::string& base_link,
             const std::string& tip_link, const double* gravity)
    : impl_(std::make_unique<Impl>(chain_of(urdf, source, base_link, tip_link), gravity)) {}

Chain::~Chain() = default;

int Chain::joint_count() const {
  return static_cast<int>(impl_->chain.getNrOfJoints());
}

int Chain::inverse_dynamics(const double* q, const double* dq, const double* ddq, double* tau) {
  Impl& s = *impl_;
  copy_in(q, s.q);
  copy_in(dq, s.dq);
  copy_in(ddq, s.ddq);
  const int status = s.id.CartToJnt(s.q, s.dq, s.ddq, s.f_ext, s.tau);
  copy_out(s.tau, tau);
  return status;
}

int Chain::mass_matrix(const double* q, double* mass) {
  Impl& s = *impl_;
  copy_in(q, s.q);
  const int status = s.dyn.JntToMass(s.q, s.mass);
  const unsigned n = s.q.rows();
  for (unsigned c = 0; c < n; ++c) {
    for (unsigned r = 0; r < n; ++r) mass[r + c * n] = s.mass(r, c);
  }
  return status;
}

int Chain::forward_dynamics(const double* q, const double* dq, const double* tau, double* ddq) {
  Impl& s = *impl_;
  copy_in(q, s.q);
  copy_in(dq, s.dq);
  copy_in(tau, s.tau);
  const int status = s.fd.CartToJnt(s.q, s.dq, s.tau, s.f_ext, s.ddq);
  copy_out(s.ddq, ddq);
  return status;
}

}  // namespace dynid::kdl
