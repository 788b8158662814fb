#pragma once

#include <string>

#include "dynid/dynamics/rnea.hpp"
#include "dynid/io/csv_table.hpp"
#include "dynid/io/joint_columns.hpp"
#include "dynid/model/model.hpp"

namespace dynid {

/// Options of inverse dynamics over a CSV file (`dynid inverse-dynamics`).
struct InverseDynamicsFileOptions {
  bool joint_terms = true;  ///< include Ia·ddq + Fv·dq + Fc·sign(dq) + Fo (false: --no-friction)
  ColumnMapping columns;    ///< renaming applied to the input header before lookup (--columns)
};

/// Joint torques for every row of `states`: reads q, dq, ddq (columns q1..qn or q_<joint>, any
/// order, others ignored; time `t` checked strictly increasing when present) and returns a table
/// with `t` (if the input has one) and tau1..taun, rows in input order, tau = rnea(q, dq, ddq)
/// (rnea.hpp; N·m or N). One Workspace is reused for all rows. Throws dynid::Error for missing
/// columns, wrong joint count or non-increasing time (file and line named).
CsvTable inverse_dynamics_table(const Model& model, const CsvTable& states,
                                const InverseDynamicsFileOptions& options = {});

/// read_csv(in_path) -> apply options.columns -> inverse_dynamics_table -> write_csv(out_path)
/// (atomic: nothing is written on error). Returns the number of rows written.
Eigen::Index inverse_dynamics_file(const Model& model, const std::string& in_path,
                                   const std::string& out_path,
                                   const InverseDynamicsFileOptions& options = {});

}  // namespace dynid
