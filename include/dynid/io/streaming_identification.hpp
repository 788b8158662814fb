#pragma once

#include <string>

#include "dynid/estimation/identification.hpp"
#include "dynid/io/joint_record_file.hpp"

namespace dynid {

/// Identification straight from a CSV file in constant memory: the file is read in chunks
/// (CsvChunkReader), each chunk's base regressor rows go into a StreamingLeastSquares factor
/// ((p+1)² numbers per joint), and nothing proportional to the number of samples is kept.
/// Requirements (else dynid::UsageError saying so): joint-side columns q*, dq*, ddq*, tau*; no
/// filtering (options.signal.filter == false), since zero-phase filtering needs the whole record.
/// Rows with |dq_j| below options.signal.zero_velocity are dropped when given (no automatic
/// threshold: it would need a second pass). Estimators: OLS or WLS (Gautier, per-joint variance
/// from the per-joint factors). Same result as identify() on the same rows, up to round-off.
IdentificationResult identify_stream(const Model& model, const std::string& path,
                                     const RunFileOptions& file, const IdentifyOptions& options);

}  // namespace dynid
