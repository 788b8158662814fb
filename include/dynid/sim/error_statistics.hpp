#pragma once

#include <Eigen/Core>

namespace dynid {

/// Statistics of an error signal and its distance to a Gaussian (seed 2 §3.5: the error PDF is
/// compared with a Gaussian one). Moments are population (maximum-likelihood) moments.
struct ErrorStatistics {
  long samples = 0;           ///< number of samples N
  double rms = 0.0;           ///< sqrt(Σ e²/N)
  double max_abs = 0.0;       ///< max |e|
  double mean = 0.0;          ///< μ = Σ e/N
  double std = 0.0;           ///< σ = sqrt(Σ (e − μ)²/N)
  double skewness = 0.0;      ///< m3/σ³ (0 for a Gaussian)
  double kurtosis = 0.0;      ///< m4/σ⁴ (3 for a Gaussian; not the excess)
  double ks_statistic = 0.0;  ///< Kolmogorov–Smirnov D = sup |F_N(e) − Φ((e − μ)/σ)|
  double ks_p_value = 1.0;    ///< asymptotic P(D_N > D) for a fully specified normal (Stephens'
                              ///< correction); optimistic here since μ, σ are estimated
                              ///< (Lilliefors) and samples of a run are correlated
};

/// Computes ErrorStatistics of e (size N ≥ 2; allocates a sorted copy). A constant e (σ = 0) gets
/// skewness = kurtosis = 0, ks_statistic = 1 and ks_p_value = 0 (no Gaussian to compare with).
/// Throws dynid::Error if e has fewer than 2 samples or a non-finite value.
ErrorStatistics error_statistics(const Eigen::Ref<const Eigen::VectorXd>& e);

/// Histogram of an error signal as an estimate of its PDF, beside the Gaussian of the same mean and
/// std (seed 2 §3.5, Fig. 8).
struct ErrorHistogram {
  Eigen::VectorXd center;    ///< bin centres [unit of e], `bins` equal bins over [min e, max e]
  Eigen::VectorXd density;   ///< count / (N · bin width): integrates to 1 [1/unit of e]
  Eigen::VectorXd gaussian;  ///< N(μ, σ²) density at the centres (0 when σ = 0)
};

/// Histogram of e (size N ≥ 2, finite) with `bins` ≥ 1 equal bins over [min e, max e] (a constant
/// e gets one bin of width 1 around it). Throws dynid::Error for fewer than 2 samples, a non-finite
/// value or bins < 1.
ErrorHistogram error_histogram(const Eigen::Ref<const Eigen::VectorXd>& e, int bins);

/// Kolmogorov survival function Q_KS(λ) = 2 Σ_{k≥1} (−1)^{k−1} exp(−2k²λ²) (Q(0) = 1).
double kolmogorov_survival(double lambda);

}  // namespace dynid
