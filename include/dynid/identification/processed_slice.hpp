#pragma once

#include <Eigen/Core>

#include "dynid/identification/record.hpp"

namespace dynid {

/// Samples first … first + count − 1 of a processed record: t, q, dq, ddq, tau (when present) and
/// the filtered Coulomb indicators moving_positive/moving_negative (when present) of those rows;
/// rate, cut-off, trim, decimation and noise as in `processed`. Row k of
/// processed_regressor() of the slice equals row first + k of the whole record's (row k of W
/// depends on sample k only), which lets callers build the regressor in chunks of bounded memory.
/// Kept apart from identification.hpp (where ProcessedRecord lives) so that its 34 includers do
/// not rebuild for it. Throws dynid::Error for a range outside the record.
ProcessedRecord processed_slice(const ProcessedRecord& processed, Eigen::Index first,
                                Eigen::Index count);

}  // namespace dynid
