// Partial results of identify --stream (issue 31 item 1): merged in any grouping and order they
// give the stream over all the runs; parts of another robot or option set are refused; truncated
// or corrupt files are refused with a message naming them.
#include <algorithm>
#include <filesystem>
#include <fstream>
#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "dynid/common/error.hpp"
#include "dynid/dynamics/rnea.hpp"
#include "dynid/identification/streaming_partial.hpp"
#include "dynid/io/csv_writer.hpp"
#include "dynid/model/robots.hpp"
#include "support/stream_runs.hpp"

namespace dynid {
namespace {

// A run of `model` (torques from RNEA, viscous friction 0.8, noise 0.2); `phase` makes runs differ.
std::string partial_test_run(const Model& model, int samples, unsigned seed, double phase,
                             const std::string& name) {
  return testing::write_stream_run(model, samples, 0.2, name, seed, phase, 0.8);
}

IdentifyOptions partial_test_options() {
  IdentifyOptions o;
  o.signal.filter = false;
  o.signal.zero_velocity = {0.05};
  o.estimator = IdentificationEstimator::kWls;
  return o;
}

// Equal up to the round-off of a different summation order: each estimate and σ within 1e-10 of
// max(|value|, σ) (a small parameter's value alone is no scale for the round-off of the sums).
void expect_same_fit(const IdentificationResult& a, const IdentificationResult& b) {
  ASSERT_EQ(a.names, b.names);
  EXPECT_EQ(a.rows, b.rows);
  EXPECT_EQ(a.samples, b.samples);
  for (Eigen::Index i = 0; i < a.estimate.x.size(); ++i) {
    const double scale = std::max(std::abs(a.estimate.x[i]), a.estimate.std_dev[i]);
    EXPECT_LE(std::abs(a.estimate.x[i] - b.estimate.x[i]), 1e-10 * scale) << a.names[i];
    EXPECT_LE(std::abs(a.estimate.std_dev[i] - b.estimate.std_dev[i]),
              1e-10 * a.estimate.std_dev[i])
        << a.names[i];
  }
  EXPECT_NEAR(a.relative_error, b.relative_error, 1e-10 * a.relative_error);
  ASSERT_EQ(a.runs.size(), b.runs.size());
  for (const RunSummary& r : a.runs) {
    const auto same = std::find_if(b.runs.begin(), b.runs.end(),
                                   [&](const RunSummary& s) { return s.file == r.file; });
    ASSERT_NE(same, b.runs.end()) << r.file;
    EXPECT_EQ(same->rows, r.rows);
    EXPECT_NEAR(same->relative_error, r.relative_error, 1e-10 * r.relative_error);
  }
}

TEST(StreamPartial, MergesInAnyGroupingAndOrderEqualTheStreamOverAllRuns) {
  const Model model = load_robot("puma560");
  std::vector<std::string> files;
  for (unsigned i = 0; i < 4; ++i) {
    files.push_back(
        partial_test_run(model, 1500, 40 + i, 0.7 * i, "partial_run" + std::to_string(i) + ".csv"));
  }
  const IdentifyOptions o = partial_test_options();
  const IdentificationResult all = identify_stream(model, files, {}, o, {1, true});
  ASSERT_EQ(all.runs.size(), 4u);
  std::vector<StreamPartial> one;
  for (const auto& f : files) one.push_back(stream_partial(model, {f}, {}, o, {2, true}));
  // Through files, as the command line and the workers of a cluster pass them.
  const std::string dir = ::testing::TempDir();
  for (std::size_t i = 0; i < one.size(); ++i) {
    write_stream_partial(dir + "/p" + std::to_string(i) + ".dpart", one[i]);
    one[i] = read_stream_partial(dir + "/p" + std::to_string(i) + ".dpart");
  }
  const auto merged = [&](const std::vector<int>& order) {
    StreamPartial m = one[order[0]];
    for (std::size_t k = 1; k < order.size(); ++k)
      merge_stream_partials(m, one[order[k]], "a", "b");
    return m;
  };
  for (const auto& order :
       {std::vector<int>{0, 1, 2, 3}, std::vector<int>{3, 1, 0, 2}, std::vector<int>{2, 0, 3, 1}}) {
    expect_same_fit(all, solve_stream_partial(model, merged(order)));
  }
  // A tree: (2 3) from one stream over two files, merged with ((1) (0)).
  StreamPartial left = stream_partial(model, {files[2], files[3]}, {}, o, {1, true});
  StreamPartial right = merged({1, 0});
  write_stream_partial(dir + "/right.dpart", right);
  merge_stream_partials(left, read_stream_partial(dir + "/right.dpart"), "left", "right");
  expect_same_fit(all, solve_stream_partial(model, left));
  // And the single-run stream is its own part solved.
  expect_same_fit(identify_stream(model, files[1], {}, o, {1, true}),
                  solve_stream_partial(model, one[1]));
}

TEST(StreamPartial, PartsOfAnotherRobotOrOptionSetAreRefused) {
  const Model puma = load_robot("puma560");
  const std::string run = partial_test_run(puma, 400, 50, 0.0, "partial_refuse.csv");
  const IdentifyOptions o = partial_test_options();
  const StreamPartial base = stream_partial(puma, {run}, {}, o);
  const auto refused = [&](const StreamPartial& other, const std::string& what) {
    StreamPartial into = base;
    try {
      merge_stream_partials(into, other, "a.dpart", "b.dpart");
      ADD_FAILURE() << "merged: " << what;
    } catch (const Error& e) {
      const std::string text = e.what();
      EXPECT_NE(text.find("'b.dpart'"), std::string::npos) << text;
      EXPECT_NE(text.find(what), std::string::npos) << text;
      EXPECT_EQ(text.find('\n'), std::string::npos) << text;
    }
    EXPECT_EQ(into.runs.size(), 1u);
  };
  IdentifyOptions no_friction = o;
  no_friction.layout.viscous = no_friction.layout.coulomb = no_friction.layout.offset = false;
  refused(stream_partial(puma, {run}, {}, no_friction), "layout");
  IdentifyOptions ols = o;
  ols.estimator = IdentificationEstimator::kOls;
  refused(stream_partial(puma, {run}, {}, ols), "estimator");
  IdentifyOptions threshold = o;
  threshold.signal.zero_velocity = {0.1};
  refused(stream_partial(puma, {run}, {}, threshold), "zero_velocity_threshold");
  refused(stream_partial(puma, {run}, {}, o, {1, false}), "accumulation");
  StreamPartial other_options = base;
  other_options.options = {{"friction", "viscous"}};
  refused(other_options, "options differ");
  // Same names, other kinematics: a longer link 2 changes the equations, not the names.
  Model longer = puma;
  longer.joints[2].p_PJ.x() += 0.05;
  refused(stream_partial(longer, {run}, {}, o), "equations differ");
  // Solving a part with another robot than it was made with.
  EXPECT_THROW(solve_stream_partial(longer, base), Error);
  const Model planar = load_robot("planar2");
  const std::string planar_run = partial_test_run(planar, 300, 51, 0.0, "partial_planar.csv");
  refused(stream_partial(planar, {planar_run}, {}, o), "robot");
}

void write_partial_bytes(const std::string& path, const std::string& bytes) {
  std::ofstream(path, std::ios::binary)
      .write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
}

// Every error names the file and says what is wrong with it, in one line.
void expect_partial_refused(const std::string& path, const std::string& what) {
  try {
    read_stream_partial(path);
    ADD_FAILURE() << "read: " << what;
  } catch (const Error& e) {
    const std::string text = e.what();
    EXPECT_NE(text.find("'" + path + "'"), std::string::npos) << text;
    EXPECT_NE(text.find(what), std::string::npos) << text;
    EXPECT_EQ(text.find('\n'), std::string::npos) << text;
  }
}

TEST(StreamPartial, TruncatedOrCorruptFilesAreRefused) {
  const Model model = load_robot("planar2");
  const std::string run = partial_test_run(model, 300, 52, 0.0, "partial_corrupt.csv");
  const std::string path = ::testing::TempDir() + "/corrupt_source.dpart";
  write_stream_partial(path, stream_partial(model, {run}, {}, partial_test_options()));
  std::ifstream in(path, std::ios::binary);
  const std::string good((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  ASSERT_GT(good.size(), 100u);
  const std::string bad = ::testing::TempDir() + "/corrupt.dpart";
  // Every cut inside the fixed header and the JSON length, then cuts every 37 bytes and the last
  // byte: refused as truncated (or, past the header, by the checksum).
  std::vector<std::size_t> cuts;
  for (std::size_t c = 0; c < 32; ++c) cuts.push_back(c);
  for (std::size_t c = 32; c < good.size(); c += 37) cuts.push_back(c);
  cuts.push_back(good.size() - 1);
  for (const std::size_t c : cuts) {
    write_partial_bytes(bad, good.substr(0, c));
    const std::string expected = c < 8 ? "not a dynid partial result" : "";
    expect_partial_refused(bad, expected);
  }
  // A flipped byte anywhere after the magic: caught (mostly by the checksum).
  for (std::size_t at = 8; at < good.size(); at += good.size() / 23) {
    std::string flipped = good;
    flipped[at] = static_cast<char>(flipped[at] ^ 0x5a);
    write_partial_bytes(bad, flipped);
    expect_partial_refused(bad, "");
  }
  std::string version = good;
  version[8] = 2;
  write_partial_bytes(bad, version);
  expect_partial_refused(bad, "format version 2");
  std::string swapped = good;
  std::reverse(swapped.begin() + 12, swapped.begin() + 16);
  write_partial_bytes(bad, swapped);
  expect_partial_refused(bad, "other byte order");
  write_partial_bytes(bad, "t,q1\n0,1\n");
  expect_partial_refused(bad, "not a dynid partial result");
  // A good file still reads.
  write_partial_bytes(bad, good);
  EXPECT_EQ(read_stream_partial(bad).runs.size(), 1u);
}

}  // namespace
}  // namespace dynid
