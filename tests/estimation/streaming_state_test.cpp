// StreamingLeastSquares::state / from_state (the partial results of issue 31) and
// relative_error, against an in-memory residual computed from W and y.
#include <limits>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "dynid/common/error.hpp"
#include "dynid/estimation/streaming_least_squares.hpp"
#include "support/estimation_support.hpp"

namespace dynid {
namespace {

using estimation_testing::gaussian;

struct StateProblem {
  Eigen::MatrixXd W;
  Eigen::VectorXd y;
  std::vector<std::vector<Eigen::Index>> columns;  // group g sees columns g..p-1
};

StateProblem state_problem(Eigen::Index samples, int G, Eigen::Index p, unsigned seed) {
  std::mt19937 rng(seed);
  StateProblem s;
  s.W = gaussian(samples * G, p, rng);
  s.columns.resize(G);
  for (int g = 0; g < G; ++g)
    for (Eigen::Index c = g; c < p; ++c) s.columns[g].push_back(c);
  for (Eigen::Index r = 0; r < s.W.rows(); ++r)
    for (Eigen::Index c = 0; c < r % G; ++c) s.W(r, c) = 0.0;
  s.y = s.W * gaussian(p, 1, rng);
  std::normal_distribution<double> nd(0.0, 0.2);
  for (Eigen::Index r = 0; r < s.y.size(); ++r) s.y(r) += nd(rng);
  return s;
}

TEST(StreamingState, RoundTripSolvesAndMergesAsTheOriginal) {
  const StateProblem s = state_problem(700, 3, 6, 5);
  for (const Accumulation a : {Accumulation::kHouseholder, Accumulation::kNormalEquations}) {
    StreamingOptions o;
    o.accumulation = a;
    o.group_columns = s.columns;
    StreamingLeastSquares all(6, 3, o), first(6, 3, o), second(6, 3, o);
    all.add(s.W, s.y);
    first.add(s.W.topRows(900), s.y.head(900));  // 900 = 300 samples: group r mod 3 stays aligned
    second.add(s.W.bottomRows(1200), s.y.tail(1200));
    const StreamingState st = first.state();
    ASSERT_EQ(st.groups.size(), 3u);
    EXPECT_EQ(st.groups[1].columns, s.columns[1]);
    StreamingLeastSquares restored = StreamingLeastSquares::from_state(st);
    EXPECT_EQ(restored.rows(), 900);
    restored.merge(StreamingLeastSquares::from_state(second.state()));
    const Estimate e = all.solve_weighted(), r = restored.solve_weighted();
    EXPECT_LT((e.x - r.x).norm(), 1e-12 * e.x.norm());
    EXPECT_LT((e.std_dev - r.std_dev).norm(), 1e-10 * e.std_dev.norm());
  }
}

TEST(StreamingState, RelativeErrorEqualsTheResidualOfTheRows) {
  const StateProblem s = state_problem(400, 3, 6, 6);
  std::mt19937 rng(7);
  const Eigen::VectorXd x = gaussian(6, 1, rng);
  // The oracle: ‖y − W x‖/‖y‖ straight from the rows.
  const double expected = (s.y - s.W * x).norm() / s.y.norm();
  for (const Accumulation a : {Accumulation::kHouseholder, Accumulation::kNormalEquations}) {
    StreamingOptions o;
    o.accumulation = a;
    o.group_columns = s.columns;
    StreamingLeastSquares lsq(6, 3, o);
    lsq.add(s.W, s.y);
    EXPECT_NEAR(lsq.relative_error(x), expected, 1e-12 * expected);
    EXPECT_THROW(lsq.relative_error(Eigen::VectorXd::Zero(5)), Error);
  }
}

TEST(StreamingState, InconsistentStatesAreRefused) {
  const StateProblem s = state_problem(50, 2, 4, 8);
  StreamingOptions o;
  o.group_columns = {{0, 1, 2, 3}, {1, 2, 3}};
  StreamingLeastSquares lsq(4, 2, o);
  lsq.add(s.W, s.y);
  const StreamingState good = lsq.state();
  EXPECT_NO_THROW(StreamingLeastSquares::from_state(good));
  StreamingState bad = good;
  bad.groups[1].summary(0, 0) = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(StreamingLeastSquares::from_state(bad), Error);
  bad = good;
  bad.groups[0].summary(3, 1) = 1.0;  // below the diagonal
  EXPECT_THROW(StreamingLeastSquares::from_state(bad), Error);
  bad = good;
  bad.groups[1].columns = {1, 3, 2};  // not sorted
  EXPECT_THROW(StreamingLeastSquares::from_state(bad), Error);
  bad = good;
  bad.groups[0].summary.conservativeResize(3, 3);
  EXPECT_THROW(StreamingLeastSquares::from_state(bad), Error);
  bad = good;
  bad.groups[0].rows = -1;
  EXPECT_THROW(StreamingLeastSquares::from_state(bad), Error);
  bad = good;
  bad.groups.clear();
  EXPECT_THROW(StreamingLeastSquares::from_state(bad), Error);
}

}  // namespace
}  // namespace dynid
