#pragma once

#include <string>

#include <nlohmann/json.hpp>

#include "dynid/model/model.hpp"
#include "dynid/sim/control_comparison.hpp"
#include "dynid/sim/simulation_validation.hpp"

namespace dynid {

/// `dynid compare-control` JSON: `controllers` (list of `name`, `joints`: list of `name`, `rms`,
/// `max`, `max_at_reversal` [rad or m], `reversals` per period), `gains` (kp, ki, kd), `samples`,
/// `reversal_window` [s], `version`.
nlohmann::json control_comparison_to_json(const Model& model, const ControlComparison& c,
                                          double reversal_window);

/// A readable table: one row per joint, RMS / max / max at reversals of each controller [deg for
/// revolute joints, mm for prismatic ones], and the computed-torque/PID ratio of the peaks.
std::string control_comparison_table(const Model& model, const ControlComparison& c);

/// Writes the error PDFs of a validation by simulation (seed 2 §3.5, Fig. 8) as CSV to `path`
/// (atomically): `bins` rows; per joint j the columns q_err<j> (bin centre [rad or m]), q_pdf<j>
/// (density [1/rad]), q_gauss<j> (Gaussian of the same mean and std), then tau_err<j>, tau_pdf<j>,
/// tau_gauss<j> [N·m, 1/(N·m)], over the samples the statistics use (error_histogram()). Throws
/// dynid::Error when the file cannot be written.
void write_error_histograms(const std::string& path, const Model& model,
                            const SimulationValidation& v, int bins = 30);

}  // namespace dynid
