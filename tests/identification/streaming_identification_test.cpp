#include <algorithm>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>
#include <thread>

#include <gtest/gtest.h>

#include "dynid/common/error.hpp"
#include "dynid/dynamics/rnea.hpp"
#include "dynid/identification/streaming_identification.hpp"
#include "dynid/io/csv_chunk_reader.hpp"
#include "dynid/io/csv_writer.hpp"
#include "dynid/model/robots.hpp"
#include "support/stream_runs.hpp"

namespace dynid {
namespace {

// A puma560 run with noisy torques written as CSV; streaming (chunked, constant memory) and
// in-memory identification must give the same estimate and statistics.
std::string write_run(const Model& model, int samples, double sigma = 0.3,
                      const std::string& name = "stream_run.csv") {
  return testing::write_stream_run(model, samples, sigma, name);
}

TEST(StreamingIdentification, EqualsInMemoryIdentification) {
  const Model model = load_robot("puma560");
  const std::string path = write_run(model, 3000);
  IdentifyOptions o;
  o.signal.filter = false;
  o.signal.zero_velocity = {0.05};
  for (auto estimator : {IdentificationEstimator::kOls, IdentificationEstimator::kWls}) {
    o.estimator = estimator;
    const IdentificationResult s = identify_stream(model, path, {}, o);
    const IdentificationResult m = identify(model, read_joint_record(path, model), o);
    ASSERT_EQ(s.names, m.names);
    EXPECT_EQ(s.rows, m.rows);
    EXPECT_LT((s.estimate.x - m.estimate.x).norm(), 1e-9 * m.estimate.x.norm());
    // The stream keeps the white-noise covariance; in memory that is std_white (std is HAC).
    EXPECT_LT((s.estimate.std_dev - m.estimate.std_dev_white).norm(),
              1e-7 * m.estimate.std_dev_white.norm());
    EXPECT_NEAR(s.relative_error, m.relative_error, 1e-10);
  }
}

std::string choice(const IdentificationResult& r, const std::string& key) {
  for (const auto& [k, v] : r.choices)
    if (k == key) return v;
  return "";
}

// Threads and normal equations change only the round-off: every combination equals the
// single-threaded Householder pass, and a fixed thread count gives bit-identical results.
TEST(StreamingIdentification, ThreadsAndNormalEquationsChangeOnlyRoundOff) {
  const Model model = load_robot("puma560");
  const std::string path = write_run(model, 20000, 0.3, "stream_threads.csv");  // 5 chunks
  IdentifyOptions o;
  o.signal.filter = false;
  o.signal.zero_velocity = {0.05};
  o.estimator = IdentificationEstimator::kWls;
  const IdentificationResult ref = identify_stream(model, path, {}, o, {1, false});
  EXPECT_EQ(choice(ref, "accumulation"), "Householder QR");
  for (int threads : {1, 2, 3}) {
    const IdentificationResult r = identify_stream(model, path, {}, o, {threads, true});
    EXPECT_NE(choice(r, "accumulation").find("normal equations"), std::string::npos);
    EXPECT_EQ(r.rows, ref.rows);
    EXPECT_EQ(r.samples, 20000);
    EXPECT_LT((r.estimate.x - ref.estimate.x).norm(), 1e-9 * ref.estimate.x.norm());
    EXPECT_LT((r.estimate.std_dev - ref.estimate.std_dev).norm(),
              1e-8 * ref.estimate.std_dev.norm());
    EXPECT_NEAR(r.relative_error, ref.relative_error, 1e-10);
    const IdentificationResult again = identify_stream(model, path, {}, o, {threads, true});
    EXPECT_EQ(again.estimate.x, r.estimate.x);  // deterministic chunk-to-worker assignment
  }
}

// Issue 16: with one worker the blocks' size does not change a bit of the estimate (the rows are
// summed in file order); with 2 and 3 workers and blocks of a line or two, only round-off.
TEST(StreamingIdentification, BlockSizeChangesOnlyRoundOff) {
  const Model model = load_robot("puma560");
  const std::string path = write_run(model, 6000, 0.3, "stream_blocks.csv");
  IdentifyOptions o;
  o.signal.filter = false;
  const IdentificationResult ref = identify_stream(model, path, {}, o, {1, true});
  for (const std::size_t bytes : {std::size_t{777}, std::size_t{4099}, std::size_t{1} << 22}) {
    const IdentificationResult one = identify_stream(model, path, {}, o, {1, true, bytes});
    EXPECT_EQ(one.estimate.x, ref.estimate.x) << bytes;
    EXPECT_EQ(one.samples, 6000);
    for (int threads : {2, 3}) {
      const IdentificationResult r = identify_stream(model, path, {}, o, {threads, true, bytes});
      EXPECT_EQ(r.rows, ref.rows);
      EXPECT_LT((r.estimate.x - ref.estimate.x).norm(), 1e-9 * ref.estimate.x.norm()) << bytes;
    }
  }
}

// The first error in file order is the one reported, whichever worker finds its error first, and
// it names the file line and data row as the sequential reader does (the oracle).
TEST(StreamingIdentification, FirstErrorInFileOrderWinsWithAnyWorkerCount) {
  const Model model = load_robot("puma560");
  const std::string clean = write_run(model, 3000, 0.3, "stream_errors.csv");
  std::string text;
  {
    std::ifstream in(clean);
    std::stringstream all;
    all << in.rdbuf();
    text = all.str();
  }
  // Replaces the second field of data row `row` (file line row + 1).
  const auto spoil = [](std::string s, int row, const std::string& with) {
    std::size_t pos = 0;
    for (int line = 0; line < row; ++line) pos = s.find('\n', pos) + 1;
    const std::size_t field = s.find(',', pos) + 1;
    s.replace(field, s.find(',', field) - field, with);
    return s;
  };
  const std::string dir = ::testing::TempDir();
  const std::vector<std::pair<std::string, std::string>> files = {
      {"stream_err_two.csv", spoil(spoil(text, 2500, "x"), 700, "nan")},
      {"stream_err_first.csv", spoil(spoil(text, 1, "1e999"), 2999, "y")},
      {"stream_err_last.csv", spoil(text, 3000, "")}};
  IdentifyOptions o;
  o.signal.filter = false;
  for (const auto& [name, content] : files) {
    const std::string path = dir + "/" + name;
    std::ofstream(path, std::ios::binary) << content;
    std::string expected;
    try {
      CsvChunkReader sequential(path);
      Eigen::MatrixXd rows;
      while (sequential.next(rows)) {
      }
    } catch (const Error& e) {
      expected = e.what();
    }
    ASSERT_NE(expected.find(name + ":"), std::string::npos) << expected;
    for (int threads : {1, 2, 3}) {
      for (const std::size_t bytes : {std::size_t{997}, std::size_t{1} << 16}) {
        try {
          identify_stream(model, path, {}, o, {threads, true, bytes});
          ADD_FAILURE() << "no error";
        } catch (const Error& e) {
          EXPECT_EQ(std::string(e.what()), expected) << threads << " workers, " << bytes;
        }
      }
    }
  }
}

// Noise-free torques make [W y] singular: the normal equations are refused and a second,
// Householder pass recovers the parameters exactly.
TEST(StreamingIdentification, NoiseFreeRunFallsBackToHouseholderPass) {
  const Model model = load_robot("puma560");
  const std::string path = write_run(model, 3000, 0.0, "stream_exact.csv");
  IdentifyOptions o;
  o.signal.filter = false;
  const IdentificationResult r = identify_stream(model, path, {}, o, {2, true});
  EXPECT_NE(choice(r, "accumulation").find("Householder QR, second pass"), std::string::npos)
      << choice(r, "accumulation");
  EXPECT_LT(r.relative_error, 1e-10);
  const IdentificationResult m = identify(model, read_joint_record(path, model), o);
  EXPECT_LT((r.estimate.x - m.estimate.x).norm(), 1e-8 * m.estimate.x.norm());
}

TEST(StreamingIdentification, NanSampleNamesTheDataRowWithAnyThreadCount) {
  const Model model = load_robot("puma560");
  const std::string path = write_run(model, 9000, 0.3, "stream_nan.csv");
  {
    std::ifstream in(path);
    std::stringstream text;
    text << in.rdbuf();
    std::string s = text.str();
    std::size_t pos = 0;
    for (int line = 0; line < 6001; ++line) pos = s.find('\n', pos) + 1;  // data row 6001
    const std::size_t q1 = s.find(',', pos) + 1;
    s.replace(q1, s.find(',', q1) - q1, "nan");  // q1 of that sample
    std::ofstream(path) << s;
  }
  IdentifyOptions o;
  o.signal.filter = false;
  for (int threads : {1, 2}) {
    try {
      identify_stream(model, path, {}, o, {threads, true});
      ADD_FAILURE() << "no error";
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find("row 6001"), std::string::npos) << e.what();
    }
  }
  EXPECT_THROW(identify_stream(model, path, {}, o, {-1, true}), UsageError);
}

// A zero-velocity list that is neither 1 nor n values is refused alike in memory and streaming.
TEST(StreamingIdentification, ZeroVelocityNeedsOneOrOnePerJoint) {
  const Model model = load_robot("puma560");
  const std::string path = write_run(model, 200, 0.3, "stream_zv.csv");
  IdentifyOptions o;
  o.signal.filter = false;
  o.signal.zero_velocity = {0.1, 0.2};
  const std::string expected = "--zero-velocity takes 1 or 6 values, got 2";
  for (int mode = 0; mode < 2; ++mode) {
    try {
      mode ? identify_stream(model, path, {}, o)
           : identify(model, read_joint_record(path, model), o);
      ADD_FAILURE() << "no error";
    } catch (const UsageError& e) {
      EXPECT_EQ(std::string(e.what()), expected);
    }
  }
  EXPECT_EQ(given_zero_velocity({0.5}, 3), Eigen::Vector3d::Constant(0.5));
  EXPECT_EQ(given_zero_velocity({}, 3).size(), 0);
}

TEST(StreamingIdentification, RefusesFilteringAndMissingDerivatives) {
  const Model model = load_robot("puma560");
  const std::string path = write_run(model, 100);
  IdentifyOptions o;  // filter on by default
  try {
    identify_stream(model, path, {}, o);
    FAIL();
  } catch (const UsageError& e) {
    EXPECT_NE(std::string(e.what()).find("--filter none"), std::string::npos);
  }
  o.signal.filter = false;
  RunFileOptions rename;
  rename.columns = {{"dq1", "v1"}};
  EXPECT_THROW(identify_stream(model, path, rename, o), Error);
}

// Progress: calls from the calling thread only (the CLI's progress line is not locked), after
// each block that thread's worker finishes, with fractions of the file's bytes that never
// decrease and end at exactly 1; a second, Householder pass says so.
TEST(StreamingIdentification, ProgressCountsTheBytesReadOnTheCallingThread) {
  const Model model = load_robot("puma560");
  const std::string path = write_run(model, 10000, 0.3, "stream_progress.csv");
  const auto bytes = std::filesystem::file_size(path);
  IdentifyOptions o;
  o.signal.filter = false;
  for (int threads : {1, 3}) {
    std::vector<double> fractions;
    bool same_thread = true, named = true;
    const auto caller = std::this_thread::get_id();
    o.progress = [&](double fraction, const std::string& what) {
      fractions.push_back(fraction);
      same_thread = same_thread && std::this_thread::get_id() == caller;
      named = named && what == "reading " + path;
    };
    // 6 blocks of a sixth of the file (less the header): the calling thread does blocks 0 and 3
    // with 3 workers, then tells the total.
    identify_stream(model, path, {}, o, {threads, true, bytes / 6});
    ASSERT_EQ(fractions.size(), threads == 1 ? 6u : 3u) << threads;
    EXPECT_TRUE(std::is_sorted(fractions.begin(), fractions.end()));
    EXPECT_GT(fractions.front(), 1.0 / 6);
    EXPECT_LT(fractions.front(), threads == 1 ? 0.2 : 0.7);
    EXPECT_EQ(fractions.back(), 1.0);
    EXPECT_TRUE(same_thread);
    EXPECT_TRUE(named);
  }
  const std::string exact = write_run(model, 3000, 0.0, "stream_progress_exact.csv");
  std::vector<std::string> what;
  o.progress = [&](double, const std::string& w) { what.push_back(w); };
  identify_stream(model, exact, {}, o, {2, true});
  ASSERT_GE(what.size(), 2u);
  EXPECT_EQ(what.front(), "reading " + exact);
  EXPECT_EQ(what.back(), "second pass (Householder QR) over " + exact);
}

}  // namespace
}  // namespace dynid
