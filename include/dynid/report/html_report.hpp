#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>
#include <nlohmann/json.hpp>

#include "dynid/identification/identify.hpp"
#include "dynid/identification/validation.hpp"

namespace dynid {

/// Where Debian's libjs-chart.js installs the Chart.js 3 bundle that reports inline.
inline constexpr const char* kChartJsPath = "/usr/share/javascript/chart.js/chart.min.js";

/// Options of html_report() (`dynid report`, `--report` of identify, validate, payload, demo).
struct HtmlReportOptions {
  /// Chart.js bundle inlined into the page, so the report opens offline.
  std::string chart_js = kChartJsPath;
  /// Heading and <title> of the page.
  std::string title = "dynid report";
};

/// One result to report: the JSON a dynid command wrote and where it came from (shown as heading).
struct ReportInput {
  std::string source;     ///< file name (or a label) shown in the report
  nlohmann::json result;  ///< the parsed result JSON
};

/// What a result JSON is, from the keys the commands write (docs/cli.md): identify (differential
/// or integral), validate (torque), validate-simulation, payload, average, excite,
/// compare-control, experiment
/// (identify --model gravity|friction|decoupled), compare (dynid compare); "generic" for anything
/// else.
std::string result_kind(const nlohmann::json& result);

/// Reads a result JSON for the report. Throws dynid::Error naming the file when it cannot be read
/// or is not a JSON object.
ReportInput read_report_input(const std::string& path);

/// One self-contained HTML page (Chart.js inlined, the data embedded, no network access) with a
/// section per input: facts (rank, condition number, errors, what was not excited), parameter
/// intervals as error bars coloured by %σ, and the plots the input carries (`plot` of identify and
/// validate: measured vs predicted torque, residual, residual histogram against the fitted
/// Gaussian with its Kolmogorov–Smirnov test, seed 2 Figs. 5 and 8; RLS histories, seed 1 Figs. 6
/// and 8; the integral model's energy fit, seed 1 Fig. 5; an excitation's trajectory and line
/// spectrum; the fits of the dedicated experiments; compare-control's tracking errors per
/// controller and joint, seed 2 Fig. 9; dynid compare's flagged changes, z-scores and trends).
/// Each chart reports itself to the page (body data-charts, data-points, data-empty-charts,
/// data-errors, data-report-status = ok when every chart has points and no script failed).
/// Throws dynid::Error when the Chart.js bundle cannot be read (install libjs-chart.js).
std::string html_report(const std::vector<ReportInput>& inputs, const HtmlReportOptions& options);

/// html_report() written atomically to `path`.
void write_html_report(const std::string& path, const std::vector<ReportInput>& inputs,
                       const HtmlReportOptions& options);

/// Options of prediction_plot_json().
struct PredictionPlotOptions {
  int max_points = 1500;       ///< samples kept per plotted series (every k-th sample)
  int histogram_bins = 41;     ///< residual histogram bins over mean ± 4σ
  int history_points = 300;    ///< RLS history points kept per parameter
  int significant_digits = 5;  ///< digits kept in the plotted numbers (smaller files)
};

/// The `plot` section of an identify or validate result: `t` [s] and per joint `measured`,
/// `predicted` torques [N·m or N] at every k-th processed sample (k so that at most max_points
/// remain), and `histogram` of the residual τ − τ̂ over every processed sample (`centers`,
/// `density` [1/(N·m)], `gaussian`: the normal density with the residual's mean and σ at the bin
/// centres, `mean`, `std`, `skewness`, `kurtosis`, `ks_statistic`, `ks_p_value` of
/// error_statistics()). Sizes: t of m samples, measured/predicted m × n.
nlohmann::json prediction_plot_json(const Eigen::VectorXd& t, const Eigen::MatrixXd& measured,
                                    const Eigen::MatrixXd& predicted,
                                    const std::vector<std::string>& joint_names,
                                    const PredictionPlotOptions& options = {});

/// The `plot` section of a validation (prediction_plot_json of its processed record).
nlohmann::json prediction_plot_json(const ValidationResult& v,
                                    const std::vector<std::string>& joint_names,
                                    const PredictionPlotOptions& options = {});

/// `history` for the plot section of an RLS identification: `t`, and per parameter `name`,
/// `value`, `std` at most history_points equations (from the first with a finite σ); null when
/// the result has no history.
nlohmann::json rls_history_plot_json(const IdentificationResult& r,
                                     const PredictionPlotOptions& options = {});

/// `energy` for the plot section of an integral-model identification (seed 1 Fig. 5): per interval
/// of the first run, its end `t` [s], the `measured` work ∫τᵀq̇ dt [J] and the integral model's
/// `predicted` (h(t_b) − h(t_a))·θ + friction work = W_b·θ̂_b [J], unweighted (integral_equations()
/// with options.integral but IntegralWeighting::kNone, on result.processed), at most max_points
/// intervals (every k-th); `decimated_every` k. W_b has exactly the columns result.names: with
/// parameters not excited (result.not_excited) the kept estimates hold their share on these data
/// (result.data_regrouping), so the kept columns alone predict the work. Null when the estimate
/// has a non-finite value. Throws dynid::Error when the estimate and result.names differ in size
/// or a name is not a base column, and as integral_equations().
nlohmann::json energy_plot_json(const Model& model, const IdentificationResult& result,
                                const IdentifyOptions& options,
                                const PredictionPlotOptions& plot_options = {});

}  // namespace dynid
