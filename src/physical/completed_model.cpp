#include "dynid/physical/completed_model.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <sstream>

#include <Eigen/Dense>
#include <Eigen/Eigenvalues>

#include "dynid/common/error.hpp"
#include "dynid/identifiability/base_parameters.hpp"
#include "dynid/model/transmission.hpp"
#include "dynid/physical/identified_model.hpp"

namespace dynid {
namespace {

std::string join(const std::vector<std::string>& names) {
  std::string list;
  for (const std::string& name : names) list += (list.empty() ? "" : ", ") + name;
  return list;
}

// The kind of a (base) parameter, which fixes its unit and order of magnitude: second moments
// (XX … ZZ, Ia: kg·m²), first moments (MX, MY, MZ: kg·m), mass, viscous, Coulomb, offset
// friction; anything else by its name without the joint index and the R of a regrouping. `link`
// receives the joint index (the digits of the name; empty when none).
std::string parameter_kind(std::string name, std::string& link) {
  if (!name.empty() && name.back() == 'R') name.pop_back();
  link.clear();
  while (!name.empty() && std::isdigit(static_cast<unsigned char>(name.back()))) {
    link.insert(link.begin(), name.back());
    name.pop_back();
  }
  for (const char* k : {"XX", "XY", "XZ", "YY", "YZ", "ZZ", "Ia"})
    if (name == k) return "second moment";
  for (const char* k : {"MX", "MY", "MZ"})
    if (name == k) return "first moment";
  if (name == "Fvp" || name == "Fvn") return "Fv";
  if (name == "Fcp" || name == "Fcn") return "Fc";
  return name;
}

// Per estimated parameter, the scale m_k of its kind (0: none): the median of |nominal| over the
// parameters of the kind on the same link whose nominal value is not 0. Nominal values, not
// estimates: the estimate of a badly determined parameter can be any size (XX4R = -250 on the
// Comau example) and would pass its neighbours' σ as small. No nominal value of the kind on the
// link: the link's parameter has no scale to borrow (the robot's other links are of other sizes:
// a wrist's MX4 against the shoulder's MX2 = 35 kg·m passed σ = 0.07 and the computed-torque
// wrist tracked 11x worse); a friction term borrows the median of max(|estimate|, |nominal|)
// of its kind over the joints (a robot model often has no nominal friction at all).
Eigen::VectorXd kind_scale(const std::vector<std::string>& names, const Eigen::VectorXd& estimate,
                           const Eigen::VectorXd& nominal) {
  const Eigen::Index e = estimate.size();
  std::vector<std::string> kind(static_cast<size_t>(e)), link(static_cast<size_t>(e));
  for (Eigen::Index i = 0; i < e; ++i)
    kind[static_cast<size_t>(i)] = parameter_kind(names[i], link[static_cast<size_t>(i)]);
  auto median = [](std::vector<double> v) {
    std::sort(v.begin(), v.end());
    const size_t h = v.size() / 2;
    return v.empty() ? 0.0 : v.size() % 2 ? v[h] : 0.5 * (v[h - 1] + v[h]);
  };
  Eigen::VectorXd out(e);
  for (Eigen::Index i = 0; i < e; ++i) {
    const auto a = static_cast<size_t>(i);
    const bool friction = kind[a] == "Fv" || kind[a] == "Fc" || kind[a] == "Fo";
    std::vector<double> same_link, joints;
    for (Eigen::Index j = 0; j < e; ++j) {
      const auto b = static_cast<size_t>(j);
      if (kind[b] != kind[a]) continue;
      joints.push_back(std::max(std::abs(estimate[j]), std::abs(nominal[j])));
      if (nominal[j] != 0.0 && link[b] == link[a]) same_link.push_back(std::abs(nominal[j]));
    }
    out[i] = !same_link.empty() ? median(same_link) : friction ? median(joints) : 0.0;
  }
  return out;
}

}  // namespace

CompletedModel complete_identified_model(
    const Model& nominal, const std::vector<std::string>& names, const Eigen::VectorXd& values,
    const Eigen::VectorXd& std_devs, const std::vector<std::string>& not_excited,
    const Eigen::MatrixXd& data_regrouping, const Eigen::MatrixXd& covariance,
    const IdentifyOptions& options, const ModelCompletionOptions& completion) {
  const auto m = static_cast<Eigen::Index>(names.size());
  const auto u = static_cast<Eigen::Index>(not_excited.size());
  const Eigen::Index e = std_devs.size();  // the estimated ones; the rest were appended, known
  if (values.size() != m || e > m ||
      (covariance.size() != 0 && (covariance.rows() != e || covariance.cols() != e)) ||
      (data_regrouping.size() != 0 &&
       (data_regrouping.rows() > m || data_regrouping.cols() != u))) {
    throw Error("complete_identified_model: values (" + std::to_string(values.size()) +
                "), std_devs, covariance and data_regrouping must match the " + std::to_string(m) +
                " names and " + std::to_string(u) + " not excited parameters");
  }
  // The base parameters of the nominal model with the result's layout (as identified_model()).
  BaseParameterOptions bo = options.base;
  bo.layout = options.layout;
  bo.coupling = options.coupling && !coupled_motors(nominal).empty();
  const BaseParameters base = compute_base_parameters(nominal, bo);
  const int p = options.layout.columns(nominal.dof());
  Eigen::VectorXd theta =
      Eigen::VectorXd::Zero(static_cast<Eigen::Index>(base.layout_names.size()));
  theta.head(p) = options.layout.parameters(nominal);
  const Eigen::VectorXd nominal_b = base.reduce(theta);
  auto index_of = [&](const std::string& name) {
    const auto it = std::find(base.names.begin(), base.names.end(), name);
    if (it == base.names.end()) {
      throw Error("parameter '" + name + "' is not a base parameter of model '" + nominal.name +
                  "' with this friction set; use the options the result was identified with");
    }
    return static_cast<Eigen::Index>(it - base.names.begin());
  };
  Eigen::VectorXd nominal_at(m);  // nominal value of each result name
  std::vector<Eigen::Index> index(static_cast<size_t>(m));
  for (Eigen::Index i = 0; i < m; ++i) {
    index[static_cast<size_t>(i)] = index_of(names[static_cast<size_t>(i)]);
    nominal_at[i] = nominal_b[index[static_cast<size_t>(i)]];
  }
  Eigen::VectorXd nominal_u(u);
  for (Eigen::Index j = 0; j < u; ++j) nominal_u[j] = nominal_b[index_of(not_excited[j])];

  CompletedModel out;
  // Not excited: each estimate holds D·θ_u; with θ_u = θ_u⁰ the estimate of its own parameter is
  // θ̂ − D·θ_u⁰.
  Eigen::VectorXd x = values;
  if (u > 0 && data_regrouping.size() != 0) {
    x.head(data_regrouping.rows()) -= data_regrouping * nominal_u;
  }
  out.nominal_not_excited = not_excited;
  if (u > 0 && data_regrouping.size() == 0) {
    out.warnings.push_back(
        "the result stores no data regroupings (written by an older dynid): the estimates still "
        "contain the not excited parameters' share on the identification data");
  }
  // Badly determined directions: in the coordinates z_i = θ_i/s_i, s_i = max(|θ̂_i|, |θ_i⁰|) (and
  // the kind's scale m_k when θ_i⁰ = 0), the eigenvectors of the covariance are independent
  // estimates; those whose σ exceeds max_relative_std (the data do not fix even the order of
  // magnitude along them) take the nominal model's component, the others keep the estimate's.
  // m_k: a parameter whose nominal value is 0 and whose estimate is within σ of 0 has no scale
  // of its own, yet a σ far below its link's nominal values of its kind (MY2 beside MX2)
  // determines it: it is 0 to within that σ. A nominal value that is not 0 is the parameter's
  // own scale and stays it.
  std::vector<Eigen::Index> bad, good;
  Eigen::VectorXd nominal_share = Eigen::VectorXd::Zero(m);  // diag of the projector
  if (e > 0 && completion.max_relative_std > 0.0) {
    if (covariance.size() != 0 && covariance.allFinite()) {
      Eigen::VectorXd scale(e);
      for (Eigen::Index i = 0; i < e; ++i)
        scale[i] = std::max(std::abs(x[i]), std::abs(nominal_at[i]));
      const Eigen::VectorXd kind = kind_scale(names, x.head(e), nominal_at.head(e));
      for (Eigen::Index i = 0; i < e; ++i) {
        if (nominal_at[i] == 0.0) scale[i] = std::max(scale[i], kind[i]);
        if (!(scale[i] > 0.0)) scale[i] = 1.0;  // all zero: any scale, nothing to move
      }
      const Eigen::MatrixXd scaled =
          scale.cwiseInverse().asDiagonal() * covariance * scale.cwiseInverse().asDiagonal();
      const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(0.5 * (scaled + scaled.transpose()));
      const double limit = completion.max_relative_std * completion.max_relative_std;
      Eigen::MatrixXd undetermined(e, 0);
      for (Eigen::Index k = 0; k < e; ++k) {
        if (eig.eigenvalues()[k] > limit) {
          undetermined.conservativeResize(Eigen::NoChange, undetermined.cols() + 1);
          undetermined.col(undetermined.cols() - 1) = eig.eigenvectors().col(k);
        }
      }
      out.undetermined_directions = static_cast<int>(undetermined.cols());
      const Eigen::VectorXd dz = (nominal_at.head(e) - x.head(e)).cwiseQuotient(scale);
      x.head(e) += scale.cwiseProduct(undetermined * (undetermined.transpose() * dz));
      nominal_share.head(e) = undetermined.rowwise().squaredNorm();
    } else {
      out.warnings.push_back(
          std::string(covariance.size() == 0
                          ? "the result stores no covariance matrix (written by an older dynid)"
                          : "the result's covariance matrix is not finite") +
          ": only the not excited parameters were filled; badly determined ones are used as "
          "estimated");
    }
  }
  for (Eigen::Index i = 0; i < m; ++i) (nominal_share[i] > 0.5 ? bad : good).push_back(i);
  for (Eigen::Index i : bad) out.nominal_badly_determined.push_back(names[static_cast<size_t>(i)]);
  // Full base vector: nominal, overwritten by the identified ones.
  out.names = base.names;
  out.values = nominal_b;
  for (Eigen::Index i : good) {
    out.values[index[static_cast<size_t>(i)]] = x[i];
    out.identified.push_back(names[static_cast<size_t>(i)]);
  }
  for (Eigen::Index i : bad) out.values[index[static_cast<size_t>(i)]] = x[i];
  // How far the filling moved the identified parameters (D·θ_u⁰ and the conditioning), in σ.
  for (Eigen::Index i : good) {
    const double s = i < e ? std_devs[i] : std::nan("");
    if (std::isfinite(s) && s > 0.0) {
      out.max_shift_sigma = std::max(out.max_shift_sigma, std::abs(x[i] - values[i]) / s);
    }
  }
  if (!out.nominal_not_excited.empty()) {
    out.warnings.push_back("not excited by the identification data, nominal values used: " +
                           join(out.nominal_not_excited));
  }
  if (out.undetermined_directions > 0) {
    std::ostringstream s;
    s << out.undetermined_directions
      << " combination(s) of the parameters are badly determined (std above "
      << completion.max_relative_std
      << " x max(|estimate|, |nominal|), or its kind's scale where the nominal is 0) and take the "
         "nominal model's values; mostly nominal now: "
      << (out.nominal_badly_determined.empty() ? std::string("none")
                                               : join(out.nominal_badly_determined));
    out.warnings.push_back(s.str());
  }
  out.model = identified_model(nominal, out.names, out.values, options);
  return out;
}

}  // namespace dynid
