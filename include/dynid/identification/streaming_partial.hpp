#pragma once

// Mergeable partial results of streaming identification (issue 31 item 1): the per-run
// least-squares state of `identify --stream` (streaming_identification.hpp), stored in a small
// versioned binary file, merged exactly with other parts and solved. The format and the meaning
// of a merge are in docs/methods/fleet.md.

#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <nlohmann/json.hpp>

#include "dynid/estimation/streaming_least_squares.hpp"
#include "dynid/identification/identify.hpp"
#include "dynid/identification/streaming_identification.hpp"
#include "dynid/model/joint_lock.hpp"
#include "dynid/model/model.hpp"

namespace dynid {

/// First 8 bytes of a partial-result file, then the format version (kStreamPartialVersion).
inline constexpr char kStreamPartialMagic[8] = {'D', 'Y', 'N', 'I', 'D', 'P', 'R', 'T'};
/// Version of the partial-result format written; readers refuse any other.
inline constexpr std::uint32_t kStreamPartialVersion = 1;

/// One run's share of a streamed identification: its rows' least-squares state alone, so that a
/// merged fit can still say how well each run is predicted (RunSummary::relative_error).
struct StreamRun {
  std::string file;          ///< the run's file as given
  Eigen::Index samples = 0;  ///< samples read
  StreamingState state;      ///< its rows' per-joint summaries (StreamingLeastSquares)
};

/// The accumulated state of `identify --stream` over one or more runs, before solving. Parts of
/// disjoint runs merge exactly (merge_stream_partials): the least-squares sums add up, and the
/// stream keeps nothing that spans two samples (no filter, no lag sums), so a merge is the stream
/// over the concatenated runs.
struct StreamPartial {
  /// What must be equal for two parts to merge, set by stream_partial(): `robot` (model name),
  /// `joints`, `parameters` (base parameter names), `layout` (armature, viscous, coulomb,
  /// offset, asymmetric, coupling), `estimator` (ols, wls), `confidence_level`,
  /// `zero_velocity_threshold` [rad/s per joint], `accumulation` (normal_equations, householder).
  nlohmann::json identity;
  /// The base regressor at fixed random states (n·probes × rank): two robots whose kinematics,
  /// gravity or parameter set differ in any way that changes the equations differ here.
  Eigen::MatrixXd probe;
  /// The caller's options (the command line's echo), equal in every merged part; stored, not read.
  nlohmann::json options = nlohmann::json::object();
  /// The caller's notes on where the part came from (the command line: the robot file as
  /// given), kept from the first part on a merge and never compared: paths differ across hosts.
  nlohmann::json origin = nlohmann::json::object();
  std::vector<StreamRun> runs;  ///< in the order accumulated / merged
};

/// The part identify_stream() solves: every file of `paths` read in blocks and accumulated
/// (StreamingIdentificationOptions; with normal_equations false, Householder from the start),
/// each run kept apart. Same requirements and errors as identify_stream(); also throws
/// dynid::UsageError for an empty `paths`.
StreamPartial stream_partial(const Model& model, const std::vector<std::string>& paths,
                             const RunFileOptions& file, const IdentifyOptions& options,
                             const StreamingIdentificationOptions& stream = {});

/// identify's options a part was accumulated with (layout, coupling, estimator, confidence level,
/// zero-velocity thresholds; no filter), rebuilt from part.identity. Throws dynid::Error when
/// the identity is malformed.
IdentifyOptions stream_partial_options(const StreamPartial& part);

/// Adds `other`'s runs to `into` (exact: the states are kept per run and summed when solved).
/// Associative and, up to round-off in the sums, commutative. Throws dynid::Error with one line
/// naming `into_name`, `other_name` and the first difference when the parts are of another
/// robot (identity or probe), option set or accumulation.
void merge_stream_partials(StreamPartial& into, const StreamPartial& other,
                           const std::string& into_name, const std::string& other_name);

/// Solves a part as identify_stream() does (OLS or WLS from the summed states, white-noise
/// covariance, per-run relative error at the joint estimate); `model` must be the robot the part
/// was accumulated on (checked against identity and probe; else dynid::Error). Throws
/// NormalEquationsError when the summed normal equations are too ill-conditioned (re-make the
/// parts with Householder accumulation), dynid::Error with too few equations.
IdentificationResult solve_stream_partial(const Model& model, const StreamPartial& part);

/// StreamPartial::origin of a part made with `robot` (name or path as given) loaded as `model`:
/// `robot`, `joints` and `locks` (the joint selection of Model::locked_joints), so that a merge
/// can load the same model without the runs' headers.
nlohmann::json stream_partial_origin(const std::string& robot, const Model& model);

/// The robot a part names in its origin and the joint selection to load it with (empty when it
/// locked nothing). Throws dynid::Error when the origin names no robot.
std::string stream_partial_robot(const StreamPartial& part, JointSelection& selection);

/// The `options` of a solved part's result JSON: part.options with `robot`, `data` (the first
/// run) and, with several runs, `data_runs`, as identify --stream over the same runs writes them.
nlohmann::json stream_partial_result_options(const StreamPartial& part, const std::string& robot);

/// Writes `part` to `path` atomically (write_file_atomic) in the format of docs/methods/fleet.md.
/// Throws dynid::Error when the file cannot be written.
void write_stream_partial(const std::string& path, const StreamPartial& part);

/// The bytes write_stream_partial writes (what crosses a network between the workers of a
/// cluster and the merge).
std::string stream_partial_bytes(const StreamPartial& part);

/// A part from the bytes of stream_partial_bytes; `path` names it in errors. Throws as
/// read_stream_partial.
StreamPartial stream_partial_from_bytes(const std::string& bytes, const std::string& path);

/// Reads a part written by write_stream_partial. Throws dynid::Error naming `path` for a file that
/// is not a part (magic), of another format version or byte order, truncated, or corrupt (sizes
/// out of range, non-finite or inconsistent state).
StreamPartial read_stream_partial(const std::string& path);

}  // namespace dynid
