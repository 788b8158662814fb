#include "dynid/physical/physical_parameters.hpp"
#include "dynid/identification/validation.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

#include <ceres/ceres.h>
#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <boost/math/distributions/chi_squared.hpp>

#include "dynid/common/error.hpp"
#include "dynid/identification/identify.hpp"

namespace dynid {

Eigen::Matrix4d pseudo_inertia(const Eigen::Ref<const Eigen::VectorXd>& link) {
  Eigen::Matrix3d I;
  I << link[0], link[1], link[2], link[1], link[3], link[4], link[2], link[4], link[5];
  Eigen::Matrix4d J;
  J.topLeftCorner<3, 3>() = 0.5 * I.trace() * Eigen::Matrix3d::Identity() - I;
  J.topRightCorner<3, 1>() = link.segment<3>(6);
  J.bottomLeftCorner<1, 3>() = link.segment<3>(6).transpose();
  J(3, 3) = link[9];
  return J;
}

namespace {

// Kinds of the per-joint columns of a layout, in joint_columns() order: which are ≥ 0.
std::vector<bool> nonnegative_joint_columns(const ParameterLayout& layout) {
  std::vector<bool> out;
  const int repeat = layout.asymmetric ? 2 : 1;
  if (layout.armature) out.push_back(true);
  if (layout.viscous) out.insert(out.end(), repeat, true);
  if (layout.coulomb) out.insert(out.end(), repeat, true);
  if (layout.offset) out.push_back(false);
  return out;
}

// φ → θ: per link the log-Cholesky factor (Rucker & Wensing 2022) U = e^α·[[e^d1, s12, s13, t1],
// [0, e^d2, s23, t2], [0, 0, e^d3, t3], [0, 0, 0, 1]], J = U·Uᵀ = [[Σ, h], [hᵀ, m]], I = tr(Σ)𝟙 −
// Σ; then the joint columns (squares where ≥ 0) and the coupling columns as they are.
struct ParameterMap {
  int links = 0;
  std::vector<bool> nonnegative;  // per joint column, repeated per joint
  int extra = 0;                  // coupling columns

  int size() const { return 10 * links + static_cast<int>(nonnegative.size()) + extra; }

  template <typename T>
  void operator()(const T* phi, T* theta) const {
    for (int l = 0; l < links; ++l) {
      const T* p = phi + 10 * l;
      const T ea = exp(p[0]);
      // Rows of U (upper triangular, last row e^α·(0 0 0 1)).
      const T u[4][4] = {{ea * exp(p[1]), ea * p[4], ea * p[5], ea * p[7]},
                         {T(0), ea * exp(p[2]), ea * p[6], ea * p[8]},
                         {T(0), T(0), ea * exp(p[3]), ea * p[9]},
                         {T(0), T(0), T(0), ea}};
      T J[4][4];
      for (int i = 0; i < 4; ++i) {
        for (int j = 0; j < 4; ++j) {
          J[i][j] = T(0);
          for (int k = 0; k < 4; ++k) J[i][j] += u[i][k] * u[j][k];
        }
      }
      T* th = theta + 10 * l;
      th[0] = J[1][1] + J[2][2];  // XX
      th[1] = -J[0][1];           // XY
      th[2] = -J[0][2];           // XZ
      th[3] = J[0][0] + J[2][2];  // YY
      th[4] = -J[1][2];           // YZ
      th[5] = J[0][0] + J[1][1];  // ZZ
      th[6] = J[0][3];
      th[7] = J[1][3];
      th[8] = J[2][3];
      th[9] = J[3][3];
    }
    int c = 10 * links;
    for (bool positive : nonnegative) {
      theta[c] = positive ? phi[c] * phi[c] : phi[c];
      ++c;
    }
    for (int e = 0; e < extra; ++e, ++c) theta[c] = phi[c];
  }
};

// θ of one link → its log-Cholesky parameters, with the mass and the second moments about the
// centre of mass raised to the given floors (a degenerate nominal body has no finite φ).
void log_cholesky_from_link(const Eigen::Ref<const Eigen::VectorXd>& link, double min_mass,
                            double min_second_moment, double* phi) {
  const Eigen::Matrix4d J = pseudo_inertia(link);
  const double m = std::max(link[9], min_mass);
  const Eigen::Vector3d c = link.segment<3>(6) / m;
  Eigen::Matrix3d A = (J.topLeftCorner<3, 3>() - m * c * c.transpose()) / m;
  A = 0.5 * (A + A.transpose());
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> es(A);
  const Eigen::Vector3d lambda = es.eigenvalues().cwiseMax(min_second_moment);
  A = es.eigenvectors() * lambda.asDiagonal() * es.eigenvectors().transpose();
  // A = U'·U'ᵀ with U' upper triangular: the Cholesky factor of the reversed matrix, reversed.
  Eigen::Matrix3d P = Eigen::Matrix3d::Zero();
  P(0, 2) = P(1, 1) = P(2, 0) = 1.0;
  const Eigen::Matrix3d L = Eigen::LLT<Eigen::Matrix3d>(P * A * P).matrixL();
  const Eigen::Matrix3d U = P * L * P;
  phi[0] = 0.5 * std::log(m);
  phi[1] = std::log(U(0, 0));
  phi[2] = std::log(U(1, 1));
  phi[3] = std::log(U(2, 2));
  phi[4] = U(0, 1);
  phi[5] = U(0, 2);
  phi[6] = U(1, 2);
  phi[7] = c[0];
  phi[8] = c[1];
  phi[9] = c[2];
}

struct DataCost {
  const ParameterMap& map;
  const BaseParameters& base;
  Eigen::MatrixXd L_inv;     // C = L·Lᵀ
  Eigen::VectorXd theta_b;   // the estimate, k values
  Eigen::MatrixXd observed;  // k × rank; empty: the identity

  template <typename T>
  bool operator()(T const* const* phi, T* residual) const {
    std::vector<T> theta(static_cast<size_t>(map.size()));
    map(phi[0], theta.data());
    std::vector<T> reduced(static_cast<size_t>(base.rank));
    for (int i = 0; i < base.rank; ++i) {
      T v = theta[static_cast<size_t>(base.base[i])];
      for (size_t j = 0; j < base.dependent.size(); ++j) {
        v += base.K_d(i, static_cast<Eigen::Index>(j)) *
             theta[static_cast<size_t>(base.dependent[j])];
      }
      reduced[static_cast<size_t>(i)] = v;
    }
    const auto k = static_cast<int>(theta_b.size());
    std::vector<T> diff(static_cast<size_t>(k));
    for (int i = 0; i < k; ++i) {
      if (observed.size() == 0) {
        diff[static_cast<size_t>(i)] = reduced[static_cast<size_t>(i)] - theta_b[i];
        continue;
      }
      T v(0);
      for (int b = 0; b < base.rank; ++b) {
        if (observed(i, b) != 0.0) v += observed(i, b) * reduced[static_cast<size_t>(b)];
      }
      diff[static_cast<size_t>(i)] = v - theta_b[i];
    }
    for (int i = 0; i < k; ++i) {
      residual[i] = T(0);
      for (int c = 0; c <= i; ++c) residual[i] += L_inv(i, c) * diff[static_cast<size_t>(c)];
    }
    return true;
  }
};

struct PriorCost {
  const ParameterMap& map;
  Eigen::VectorXd nominal, scale;  // residual_i = (θ_i − nominal_i)/scale_i

  template <typename T>
  bool operator()(T const* const* phi, T* residual) const {
    std::vector<T> theta(static_cast<size_t>(map.size()));
    map(phi[0], theta.data());
    for (Eigen::Index i = 0; i < nominal.size(); ++i) {
      residual[i] = (theta[static_cast<size_t>(i)] - nominal[i]) / scale[i];
    }
    return true;
  }
};

// Ends the solve successfully once the cost has stalled: less than `tolerance`·cost gained over
// the last `window` iterations (PhysicalFitOptions::stall_tolerance). Ceres' own function
// tolerance looks at one step, and single steps in the valley vary by orders of magnitude.
class StallCallback : public ceres::IterationCallback {
 public:
  StallCallback(double tolerance, int window) : tolerance_(tolerance), window_(window) {}
  ceres::CallbackReturnType operator()(const ceres::IterationSummary& summary) override {
    costs_.push_back(summary.cost);
    const size_t k = costs_.size();
    if (window_ <= 0 || k <= static_cast<size_t>(window_)) return ceres::SOLVER_CONTINUE;
    // A rise over the window is a non-monotone excursion, not a stall: let it play out.
    const double gain = costs_[k - 1 - static_cast<size_t>(window_)] - costs_[k - 1];
    if (gain >= 0.0 && gain < tolerance_ * costs_[k - 1]) {
      stalled_ = true;
      return ceres::SOLVER_TERMINATE_SUCCESSFULLY;
    }
    return ceres::SOLVER_CONTINUE;
  }
  bool stalled() const { return stalled_; }

 private:
  double tolerance_;
  int window_;
  bool stalled_ = false;
  std::vector<double> costs_;
};

}  // namespace

PhysicalFit physical_parameters(const Model& nominal, const BaseParameters& base,
                                const ParameterLayout& layout, const Eigen::VectorXd& theta_b,
                                const Eigen::MatrixXd& covariance,
                                const PhysicalFitOptions& options,
                                const Eigen::MatrixXd& observed) {
  const int n = nominal.dof();
  ParameterMap map;
  map.links = n;
  const std::vector<bool> per_joint = nonnegative_joint_columns(layout);
  for (int j = 0; j < n; ++j)
    map.nonnegative.insert(map.nonnegative.end(), per_joint.begin(), per_joint.end());
  map.extra = static_cast<int>(base.layout_names.size()) - layout.columns(n);
  const Eigen::Index k = observed.size() == 0 ? base.rank : observed.rows();
  if (map.extra < 0 || theta_b.size() != k || covariance.rows() != k || covariance.cols() != k ||
      (observed.size() != 0 && observed.cols() != base.rank)) {
    throw Error("physical parameters: the base set (" + std::to_string(base.rank) +
                " parameters) does not match the estimate (" + std::to_string(theta_b.size()) +
                ") or its covariance; identify and fit with the same model and friction options");
  }
  if (!theta_b.allFinite() || !covariance.allFinite()) {
    throw Error("physical parameters: the estimate or its covariance is not finite");
  }
  const Eigen::LLT<Eigen::MatrixXd> llt(0.5 * (covariance + covariance.transpose()));
  if (llt.info() != Eigen::Success) {
    throw Error(
        "physical parameters: the covariance of the estimate is not positive definite (a "
        "parameter the data do not determine); excite it or leave it out before --physical");
  }
  const Eigen::MatrixXd L = llt.matrixL();
  const int P = map.size();
  Eigen::VectorXd theta_nom = Eigen::VectorXd::Zero(P);
  theta_nom.head(layout.columns(n)) = layout.parameters(nominal);

  // Start: the nominal links (floors for degenerate bodies), the joint terms of the estimate where
  // they are base parameters themselves, else nominal.
  double max_mass = 0.0;
  for (int l = 0; l < n; ++l) max_mass = std::max(max_mass, theta_nom[10 * l + 9]);
  // The fit is drawn towards the nominal links, and its distance is relative to them: a model
  // with no mass anywhere (a URDF without <inertial> blocks) gives neither a target nor a scale.
  if (!(max_mass > 0.0)) {
    throw Error("physical parameters: the nominal model '" + nominal.name +
                "' has no mass on any moving link (a URDF without <inertial> blocks?); the "
                "consistent fit stays as close as the data allow to the nominal inertias, so "
                "give each link's nominal <inertial> (CAD, datasheet)");
  }
  const double min_mass = 1e-3 * std::max(max_mass, 1.0);
  Eigen::VectorXd phi(P);
  for (int l = 0; l < n; ++l) {
    log_cholesky_from_link(theta_nom.segment<10>(10 * l), min_mass, options.min_second_moment,
                           phi.data() + 10 * l);
  }
  Eigen::VectorXd start_theta = theta_nom;
  for (int i = 0; i < base.rank; ++i) {
    if (base.base[i] < 10 * n) continue;
    if (observed.size() == 0) {
      start_theta[base.base[i]] = theta_b[i];
      continue;
    }
    // With data regroupings: the estimate of a kept joint term that holds itself alone.
    for (Eigen::Index r = 0; r < k; ++r) {
      if (observed(r, i) == 1.0 && observed.row(r).cwiseAbs().sum() == 1.0)
        start_theta[base.base[i]] = theta_b[r];
    }
  }
  for (int c = 10 * n; c < P; ++c) {
    const bool positive = c - 10 * n < static_cast<int>(map.nonnegative.size()) &&
                          map.nonnegative[static_cast<size_t>(c - 10 * n)];
    // A square root at 0 has no gradient: start a nonnegative term slightly inside.
    phi[c] = positive ? std::sqrt(std::max(start_theta[c], 1e-6)) : start_theta[c];
  }

  // Prior scales: the nominal value, floored per kind at 1 % of the largest of that kind.
  Eigen::VectorXd scale(P);
  for (int c = 0; c < P; ++c) {
    double kind_max = 0.0;
    if (c < 10 * n) {
      for (int l = 0; l < n; ++l)
        kind_max = std::max(kind_max, std::abs(theta_nom[10 * l + c % 10]));
    } else {
      kind_max = theta_nom.tail(P - 10 * n).cwiseAbs().maxCoeff();
    }
    scale[c] = std::abs(theta_nom[c]) + 0.01 * std::max(kind_max, 1e-3);
  }

  ceres::Problem problem;
  auto* data = new ceres::DynamicAutoDiffCostFunction<DataCost, 4>(new DataCost{
      map, base, L.triangularView<Eigen::Lower>().solve(Eigen::MatrixXd::Identity(k, k)), theta_b,
      observed});
  data->AddParameterBlock(P);
  data->SetNumResiduals(static_cast<int>(k));
  problem.AddResidualBlock(data, nullptr, phi.data());
  auto* prior = new ceres::DynamicAutoDiffCostFunction<PriorCost, 4>(
      new PriorCost{map, start_theta, scale / std::sqrt(options.prior_weight)});
  prior->AddParameterBlock(P);
  prior->SetNumResiduals(P);
  problem.AddResidualBlock(prior, nullptr, phi.data());
  // The exponents stay where e^(2x) is finite (|x| ≤ 30 spans masses and moments from 1e-26 to
  // 1e26): a trial step beyond would give an infinite residual.
  for (int l = 0; l < n; ++l) {
    for (int k = 0; k < 4; ++k) {
      problem.SetParameterLowerBound(phi.data(), 10 * l + k, -30.0);
      problem.SetParameterUpperBound(phi.data(), 10 * l + k, 30.0);
    }
  }
  ceres::Solver::Options so;
  so.linear_solver_type = ceres::DENSE_QR;
  so.max_num_iterations = options.max_iterations;
  so.function_tolerance = 1e-14;
  so.parameter_tolerance = 1e-14;
  so.gradient_tolerance = 1e-16;
  so.logging_type = ceres::SILENT;
  so.num_threads = 1;
  // The data fix only the base combinations; along the rest the cost is the weak prior, a long
  // flat valley in which monotone steps crawl.
  so.use_nonmonotonic_steps = true;
  StallCallback stall(options.stall_tolerance, options.stall_window);
  so.callbacks.push_back(&stall);
  ceres::Solver::Summary cs;
  ceres::Solve(so, &problem, &cs);

  PhysicalFit out;
  out.names = base.layout_names;
  out.theta.resize(P);
  map(phi.data(), out.theta.data());
  if (!out.theta.allFinite()) {
    throw Error("physical parameters: the fit diverged (" + cs.message + ")");
  }
  out.theta_b = base.reduce(out.theta);
  const Eigen::VectorXd fitted = observed.size() == 0 ? out.theta_b : observed * out.theta_b;
  out.mahalanobis = (L.triangularView<Eigen::Lower>().solve(fitted - theta_b)).norm();
  out.chi2_limit = std::sqrt(boost::math::quantile(boost::math::chi_squared(static_cast<double>(k)),
                                                   options.confidence_level));
  out.within_limit = out.mahalanobis <= out.chi2_limit;
  const Eigen::VectorXd d_links = out.theta.head(10 * n) - theta_nom.head(10 * n);
  out.nominal_distance = d_links.norm() / std::max(theta_nom.head(10 * n).norm(), 1e-300);
  out.min_pseudo_inertia_eigenvalue.resize(n);
  for (int l = 0; l < n; ++l) {
    out.min_pseudo_inertia_eigenvalue[l] = Eigen::SelfAdjointEigenSolver<Eigen::Matrix4d>(
                                               pseudo_inertia(out.theta.segment<10>(10 * l)))
                                               .eigenvalues()
                                               .minCoeff();
  }
  // J = U·Uᵀ is positive definite by construction; a link whose smallest moment is below the
  // rounding of the largest one is reported as it is (degenerate), not as inconsistent.
  out.consistent = true;
  for (int l = 0; l < n; ++l) {
    const double scale = pseudo_inertia(out.theta.segment<10>(10 * l)).cwiseAbs().maxCoeff();
    out.consistent = out.consistent && out.min_pseudo_inertia_eigenvalue[l] >= -1e-12 * scale;
  }
  out.iterations = static_cast<int>(cs.iterations.size());
  out.converged = cs.termination_type == ceres::CONVERGENCE || stall.stalled();
  if (!out.within_limit && options.refuse_beyond_limit) {
    std::ostringstream m;
    m.precision(3);
    m << "no physically consistent parameter set lies near the identified values: the nearest is "
      << out.mahalanobis << " sigma away (limit " << out.chi2_limit << " at "
      << 100.0 * options.confidence_level
      << " %); the model lacks a term the data need (friction, a coupling, a payload), or the "
         "intervals are too narrow";
    throw Error(m.str());
  }
  return out;
}

PhysicalCheck physical_parameters_of_result(const Model& model, const IdentificationResult& result,
                                            const IdentifyOptions& options, const JointRecord& run,
                                            const std::string& option,
                                            std::optional<double> free_error) {
  // A parameter the data did not determine has no σ of its own: the estimates observe the kept
  // base parameters plus their data regroupings, θ̂_k = θ_k + D·θ_u, and the consistent set is
  // fitted to that; θ_u then follows the pull towards the nominal model.
  PhysicalCheck out;
  Eigen::MatrixXd observed;
  if (!result.not_excited.empty()) {
    const auto index_of = [&](const std::string& name) {
      const auto it = std::find(result.base.names.begin(), result.base.names.end(), name);
      if (it == result.base.names.end())
        throw Error(option + ": '" + name + "' is not a base parameter of the result's model");
      return static_cast<Eigen::Index>(it - result.base.names.begin());
    };
    const auto kept = static_cast<Eigen::Index>(result.names.size());
    observed = Eigen::MatrixXd::Zero(kept, result.base.rank);
    for (Eigen::Index i = 0; i < kept; ++i)
      observed(i, index_of(result.names[static_cast<size_t>(i)])) = 1.0;
    for (size_t u = 0; u < result.not_excited.size(); ++u) {
      const Eigen::Index b = index_of(result.not_excited[u]);
      for (Eigen::Index i = 0; i < std::min(kept, result.data_regrouping.rows()); ++i)
        observed(i, b) += result.data_regrouping(i, static_cast<Eigen::Index>(u));
    }
    out.warnings.push_back(
        "not excited by the data, so set by the consistent model nearest the nominal one: " + [&] {
          std::string list;
          for (const auto& name : result.not_excited) list += (list.empty() ? "" : ", ") + name;
          // Why they are not excited, when the joints moved but together (issue 26 item 5).
          for (const LockstepJoints& pair : result.lockstep)
            list += "; " + lockstep_text(model, pair);
          return list;
        }());
  } else {
    for (const LockstepJoints& pair : result.lockstep)
      out.warnings.push_back(lockstep_text(model, pair) +
                             "; until then the consistent set keeps the nominal model's values "
                             "where the data leave freedom");
  }
  out.fit = physical_parameters(model, result.base, options.layout, result.estimate.x,
                                result.estimate.covariance, {}, observed);
  IdentifyOptions same = options;
  same.signal.cutoff_hz = result.processed.cutoff_hz;
  out.physical_error =
      validate_torques(model, run, result.base.names, out.fit.theta_b, same).relative_error_all;
  out.free_error = free_error ? *free_error
                              : validate_torques(model, run, result.names, result.estimate.x, same,
                                                 result.not_excited)
                                    .relative_error_all;
  if (!out.fit.within_limit) {
    std::ostringstream m;
    m.precision(3);
    m << "the nearest physically consistent parameter set is " << out.fit.mahalanobis
      << " sigma from the estimate (limit " << out.fit.chi2_limit
      << "): beyond what the intervals allow, the model lacks a term the data need (friction, a "
         "coupling, a payload) or the intervals are too narrow; it is returned with its torque "
         "error, "
      << 100.0 * out.physical_error << " % against " << 100.0 * out.free_error
      << " % unconstrained";
    out.warnings.push_back(m.str());
  }
  return out;
}

}  // namespace dynid
