#pragma once

#include <functional>
#include <string>
#include <vector>

#include "dynid/excitation/excitation_optimization.hpp"
#include "dynid/identification/identify.hpp"
#include "dynid/identification/validation.hpp"
#include "dynid/report/html_report.hpp"

namespace dynid {

/// Options of the end-to-end demo (issue 5 item 5).
struct DemoOptions {
  std::string robot = "puma560";  ///< built-in name or model path
  std::string out_dir;            ///< folder for every file written (created)
  int periods = 25;               ///< excitation periods run on the plant (seed 2 §3.4)
  double f0 = 0.2;                ///< fundamental frequency of the excitation [Hz]
  int harmonics = 5;              ///< harmonics per joint
  double rate = 1000.0;           ///< controller and sampling rate [Hz]
  bool mujoco = true;             ///< MuJoCo plant (else dynid's own)
  double torque_noise = 0.2;      ///< torque sensor noise std [N·m]
  double position_noise = 2e-5;   ///< position sensor noise std [rad]
  unsigned seed = 7;              ///< noise and optimiser seed
};

/// What the demo found: identified vs true base parameters and the validation errors.
struct DemoResult {
  IdentificationResult identification;
  /// True value of each identified parameter (identification.names): the model's values reduced
  /// to base parameters, plus the data regrouping of any not excited (estimated_base_values).
  Eigen::VectorXd truth;
  ExcitationResult excitation;
  ValidationResult validation;  ///< torque prediction on a trapezoidal move
  std::string table;            ///< the printed summary
  /// The JSON files written, as read_report_input() would read them back: excitation.json,
  /// result.json, validation.json (the caller's report needs no file, so a batch of pending
  /// outputs, io/atomic_file.hpp, can hold them until everything has succeeded).
  std::vector<ReportInput> reports;
};

/// Runs the whole loop on a simulated robot: optimise an excitation (condition number), run it for
/// `periods` periods in closed loop (PID + computed-torque feed-forward) on the plant with sensor
/// noise and quantisation, average the periods (seed 2 §3.4), filter and identify the base
/// parameters with confidence intervals, and validate on a trapezoidal move. Writes traj.csv,
/// excitation.json, run.csv, averaged.csv, result.json, validation_run.csv and validation.json to
/// out_dir. `progress` receives one line per stage.
DemoResult run_demo(const DemoOptions& options,
                    const std::function<void(const std::string&)>& progress);

}  // namespace dynid
