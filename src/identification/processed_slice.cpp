#include "dynid/identification/processed_slice.hpp"

#include <string>

#include "dynid/common/error.hpp"

namespace dynid {

ProcessedRecord processed_slice(const ProcessedRecord& processed, Eigen::Index first,
                                Eigen::Index count) {
  const Eigen::Index m = processed.record.t.size();
  if (first < 0 || count < 0 || first + count > m)
    throw Error("processed_slice: samples " + std::to_string(first) + " + " +
                std::to_string(count) + " outside the record's " + std::to_string(m));
  ProcessedRecord out;
  out.rate_hz = processed.rate_hz;
  out.cutoff_hz = processed.cutoff_hz;
  out.trim = processed.trim;
  out.decimate = processed.decimate;
  out.position_noise_std = processed.position_noise_std;
  out.velocity_noise_std = processed.velocity_noise_std;
  const JointRecord& r = processed.record;
  out.record.t = r.t.segment(first, count);
  out.record.q = r.q.middleRows(first, count);
  out.record.dq = r.dq.middleRows(first, count);
  out.record.ddq = r.ddq.middleRows(first, count);
  if (r.tau.rows() == m) out.record.tau = r.tau.middleRows(first, count);
  if (processed.moving_positive.rows() == m) {
    out.moving_positive = processed.moving_positive.middleRows(first, count);
    out.moving_negative = processed.moving_negative.middleRows(first, count);
  }
  return out;
}

}  // namespace dynid
