#pragma once

#include <string>

#include "dynid/estimation/identification.hpp"
#include "dynid/io/joint_columns.hpp"
#include "dynid/model/model.hpp"

namespace dynid {

/// How to read a recorded run (DESIGN.md §4).
struct RunFileOptions {
  ColumnMapping columns;  ///< renames applied before lookup (`--columns from=to,...`)
  double rate_hz = 0.0;   ///< sample rate when the file has no `t` column [Hz]; 0 = need `t`
};

/// Reads a run into a joint-side record: time from `t` (or `rate_hz`), positions from `q*`
/// (joint side) or `qm*` (motor side, converted with the model's transmission,
/// q = N⁻¹·qm + q_offset), torques from `tau*` or `taum*` (tau = Nᵀ·taum), and `dq*`, `ddq*` when
/// present (used as given). Columns `q<j>` or `q_<joint name>`; other columns ignored.
/// Throws dynid::Error naming the file for missing columns (and the fix), no time information,
/// both joint- and motor-side columns, or bad numbers (see read_csv).
JointRecord read_joint_record(const std::string& path, const Model& model,
                              const RunFileOptions& options = {});

/// Reads a reference trajectory (`t`, `q*`, optional `dq*`, `ddq*`, e.g. from dynid excite) into
/// a record with an empty tau; missing derivatives are central differences on the time stamps.
/// Throws dynid::Error naming the file for a missing `t` or q columns.
JointRecord read_reference(const std::string& path, const Model& model,
                           const RunFileOptions& options = {});

}  // namespace dynid
