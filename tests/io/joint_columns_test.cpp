#include "dynid/io/joint_columns.hpp"

#include <gtest/gtest.h>

#include "dynid/io/csv_reader.hpp"
#include "io/io_test_support.hpp"

namespace dynid {
namespace {

using test::error_of;

const std::vector<std::string> kJoints{"shoulder", "elbow"};

TEST(JointColumns, NumberedNamedAnyOrderExtraColumnsIgnored) {
  const CsvTable t = read_csv(std::string(DYNID_SOURCE_DIR) + "/tests/data/csv/named_columns.csv");
  // Header: t,q_elbow,ddq2,dq_shoulder,q1,ddq_shoulder,dq2
  EXPECT_EQ(resolve_joint_columns(t.columns, kJoints, "q", t.source),
            (std::vector<Eigen::Index>{4, 1}));
  EXPECT_EQ(resolve_joint_columns(t.columns, kJoints, "dq", t.source),
            (std::vector<Eigen::Index>{3, 6}));
  EXPECT_EQ(resolve_joint_columns(t.columns, kJoints, "ddq", t.source),
            (std::vector<Eigen::Index>{5, 2}));
  const Eigen::MatrixXd q = joint_signal(t, kJoints, "q");
  Eigen::MatrixXd expected(2, 2);
  expected << 0.25, 0.5, 1.0, -0.5;
  EXPECT_EQ(q, expected);
  EXPECT_TRUE(has_joint_columns(t.columns, kJoints, "dq"));
  EXPECT_FALSE(has_joint_columns(t.columns, kJoints, "tau"));
  // Prefixes do not capture each other: qr1 / qm1 are not q columns.
  const std::vector<std::string> cols{"qr1", "qm1", "q2", "q1", "taum1", "tau1", "tau2"};
  EXPECT_EQ(resolve_joint_columns(cols, kJoints, "q", "f"), (std::vector<Eigen::Index>{3, 2}));
  EXPECT_EQ(resolve_joint_columns(cols, kJoints, "tau", "f"), (std::vector<Eigen::Index>{5, 6}));
}

TEST(JointColumns, MissingColumnsNamedWithHeader) {
  const std::vector<std::string> cols{"t", "q1", "q2", "dq1"};
  const std::string m = error_of([&] { resolve_joint_columns(cols, kJoints, "dq", "s.csv"); });
  EXPECT_HAS(m, "s.csv: missing column dq2 (or dq_<joint name>)");
  EXPECT_HAS(m, "available columns: t,q1,q2,dq1");
  EXPECT_HAS(m, "--columns");
  EXPECT_HAS(error_of([&] { resolve_joint_columns(cols, kJoints, "ddq", "s.csv"); }),
             "missing columns ddq1,ddq2");
}

TEST(JointColumns, WrongJointCount) {
  const std::vector<std::string> six{"j1", "j2", "j3", "j4", "j5", "j6"};
  const std::vector<std::string> cols{"t", "q1", "q2", "q3", "q4", "q5"};
  EXPECT_HAS(error_of([&] { resolve_joint_columns(cols, six, "q", "s.csv"); }),
             "s.csv: missing column q6 (or q_<joint name>); the file has columns q1..q5 (5 joints) "
             "but the model has 6 joints; available columns: t,q1,q2,q3,q4,q5");
  const std::vector<std::string> three{"q1", "q2", "q3"};
  EXPECT_HAS(error_of([&] { resolve_joint_columns(three, kJoints, "q", "s.csv"); }),
             "s.csv: has columns q1..q3 but the model has 2 joints");
}

TEST(JointColumns, BothFormsForOneJointIsAnError) {
  const std::vector<std::string> cols{"q1", "q_shoulder", "q2"};
  EXPECT_HAS(error_of([&] { resolve_joint_columns(cols, kJoints, "q", "s.csv"); }),
             "joint 1 has both columns 'q1' and 'q_shoulder'");
}

TEST(JointColumns, MappingRenamesBeforeLookup) {
  CsvTable t = parse_csv("time,pos_a,pos_b\n0,1,2\n", "m.csv");
  apply_column_mapping(t, parse_column_mapping(" pos_a=q1 , pos_b=q_elbow,time=t"));
  EXPECT_EQ(t.columns, (std::vector<std::string>{"t", "q1", "q_elbow"}));
  EXPECT_EQ(resolve_joint_columns(t.columns, kJoints, "q", t.source),
            (std::vector<Eigen::Index>{1, 2}));
  EXPECT_TRUE(parse_column_mapping("").empty());
  EXPECT_THROW(parse_column_mapping("a=b,c"), UsageError);
  EXPECT_THROW(parse_column_mapping("a=b,a=c"), UsageError);
  EXPECT_HAS(error_of([&] {
               apply_column_mapping(t, {{"nope", "q2"}});
             }),
             "m.csv: --columns names 'nope', which is not in the header (t,q1,q_elbow)");
  EXPECT_HAS(error_of([&] { apply_column_mapping(t, {{"t", "q1"}}); }), "column 'q1' twice");
}

TEST(JointColumns, TimeMustBeStrictlyIncreasing) {
  EXPECT_FALSE(checked_time_column(parse_csv("q1\n0\n", "a.csv")).has_value());
  EXPECT_EQ(*checked_time_column(parse_csv("q1,t\n0,0\n0,0.1\n", "a.csv")), 1);
  const std::string m =
      error_of([] { checked_time_column(parse_csv("t,q1\n0,0\n# c\n0.1,0\n0.1,0\n", "a.csv")); });
  EXPECT_HAS(m, "a.csv:5: time t = 0.10000000000000001 is not greater than");
  EXPECT_HAS(m, "on line 4; time must be strictly increasing");
}

}  // namespace
}  // namespace dynid
