#pragma once

#include <string>
#include <vector>

#include "dynid/identification/identify.hpp"
#include "dynid/io/joint_record_file.hpp"

namespace dynid {

/// Options of identify_stream that do not change the result beyond round-off.
struct StreamingIdentificationOptions {
  /// Worker threads, each reading, parsing and accumulating its own blocks of the file (there is
  /// no separate reader thread; the calling thread is one of them); 0 = one per core, at most 8.
  /// Block b goes to worker b mod threads and the workers' sums are merged in worker order, so
  /// the result does not depend on timing.
  int threads = 0;
  /// Accumulate normal equations (≈ 3× faster than Householder updates) and fall back to a second,
  /// Householder pass over the file when they are not accurate enough
  /// (StreamingLeastSquares::normal_equations_accurate). false: Householder from the start.
  bool normal_equations = true;
  /// Bytes of the file per block (CsvBlockOptions::block_bytes; > 0): about a core's L2 cache.
  std::size_t block_bytes = std::size_t{256} << 10;
};

/// Identification straight from a CSV file in constant memory: the file is read in blocks
/// (CsvBlockReader), each block's base regressor rows go into per-joint StreamingLeastSquares
/// summaries ((p_j+1)² numbers per joint, p_j = base columns joint j can see: links of its
/// subtree and its own friction), and nothing proportional to the number of samples is kept.
/// Requirements (else dynid::UsageError saying so): joint-side columns q*, dq*, ddq*, tau*; no
/// filtering (options.signal.filter == false), since zero-phase filtering needs the whole record,
/// and no other signal option away from its default (cut-off, decimation, trim, Savitzky–Golay,
/// torque time offset, filtered Coulomb columns); finite, non-negative zero-velocity thresholds.
/// Rows with |dq_j| below options.signal.zero_velocity are dropped when given (no automatic
/// threshold: it would need a second pass). Estimators: OLS or WLS (Gautier, per-joint variance
/// from the per-joint factors). Same result as identify() on the same rows, up to round-off.
/// options.progress (may be empty) is told the fraction of the file's bytes done after each block
/// the calling thread's worker finishes (and at the end), from the calling thread (a second,
/// Householder pass starts again from 0 and says so).
/// Throws dynid::Error naming the file row for NaN/Inf samples and malformed lines.
IdentificationResult identify_stream(const Model& model, const std::string& path,
                                     const RunFileOptions& file, const IdentifyOptions& options,
                                     const StreamingIdentificationOptions& stream = {});

/// identify_stream over several runs (files), each read as above; the fit is that of all their
/// rows (no row spans two files, so this is the stream over the concatenated runs) and
/// IdentificationResult::runs has one entry per file with its relative error at the joint
/// estimate. Throws as identify_stream, and dynid::UsageError for an empty `paths`.
IdentificationResult identify_stream(const Model& model, const std::vector<std::string>& paths,
                                     const RunFileOptions& file, const IdentifyOptions& options,
                                     const StreamingIdentificationOptions& stream = {});

}  // namespace dynid
