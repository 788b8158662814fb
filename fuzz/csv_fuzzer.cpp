// libFuzzer harness for the CSV readers: the in-memory reader (parse_csv), the streaming reader
// (CsvChunkReader, with a tiny buffer so that line and buffer boundaries are exercised) and the run
// reader on top (read_joint_record for the built-in planar2), and the block reader of
// identify_stream (CsvBlockReader, blocks of a few bytes). All implement one format
// (csv_reader.hpp), so they must accept the same inputs and return the same numbers. An accepted
// run then goes through a one-joint experiment and an abandoned batch of outputs.

#include <cstdint>
#include <fstream>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "dynid/experiments/decoupled_model.hpp"
#include "dynid/identification/record.hpp"
#include "dynid/io/atomic_file.hpp"
#include "dynid/io/csv_chunk_reader.hpp"
#include "dynid/io/csv_reader.hpp"
#include "dynid/io/joint_record_file.hpp"
#include "dynid/io/json_writer.hpp"
#include "dynid/model/robots.hpp"
#include "fuzz_support.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace dynid;
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  bool memory_ok = false;
  CsvTable table;
  fuzz::expect_clean([&] {
    table = parse_csv(text, "fuzz.csv");
    memory_ok = true;
  });
  if (memory_ok) {
    fuzz::require(table.data.cols() == static_cast<Eigen::Index>(table.columns.size()),
                  "one data column per header name");
    fuzz::require(table.data.allFinite(), "parse_csv rejects NaN/Inf");
  }

  const std::string path = fuzz::scratch_file(data, size, ".csv");
  bool stream_ok = false;
  std::string stream_error;
  Eigen::MatrixXd streamed(0, 0);
  fuzz::expect_clean([&] {
    try {
      CsvChunkOptions options;
      options.chunk_rows = 3;
      options.buffer_bytes = 16;
      CsvChunkReader reader(path, options);
      Eigen::MatrixXd block;
      streamed.resize(0, static_cast<Eigen::Index>(reader.columns().size()));
      while (reader.next(block)) {
        Eigen::MatrixXd grown(streamed.rows() + block.rows(), streamed.cols());
        grown << streamed, block;
        streamed.swap(grown);
      }
      stream_ok = true;
    } catch (const Error& e) {
      stream_error = e.what();
      throw;
    }
  });
  fuzz::require(memory_ok == stream_ok, "parse_csv and CsvChunkReader accept the same files");
  if (memory_ok && stream_ok) {
    fuzz::require(streamed.rows() == table.data.rows() && streamed.cols() == table.data.cols() &&
                      (streamed.array() == table.data.array()).all(),
                  "parse_csv and CsvChunkReader return the same numbers");
  }

  // CsvBlockReader (identify_stream's parallel reader) with blocks of 1 to 7 bytes, so that lines
  // start, end and cross block boundaries everywhere: the same files, numbers and first error.
  bool blocks_ok = false;
  std::string block_error;
  Eigen::MatrixXd blocked(0, 0);
  fuzz::expect_clean([&] {
    try {
      const CsvBlockReader reader(path, {1 + size % 7});
      CsvBlock block;
      blocked.resize(0, static_cast<Eigen::Index>(reader.columns().size()));
      for (std::int64_t b = 0; b < reader.blocks(); ++b) {
        reader.parse(b, block);
        Eigen::MatrixXd grown(blocked.rows() + block.rows.rows(), blocked.cols());
        grown << blocked, block.rows;
        blocked.swap(grown);
      }
      blocks_ok = true;
    } catch (const Error& e) {
      block_error = e.what();
      throw;
    }
  });
  fuzz::require(blocks_ok == stream_ok && block_error == stream_error,
                "CsvChunkReader and CsvBlockReader accept the same files, with the same errors");
  if (blocks_ok && stream_ok) {
    fuzz::require(blocked.rows() == streamed.rows() && blocked.cols() == streamed.cols() &&
                      (blocked.array() == streamed.array()).all(),
                  "CsvChunkReader and CsvBlockReader return the same numbers");
  }

  static const Model planar2 = load_robot("planar2");
  fuzz::expect_clean([&] {
    const JointRecord record = read_joint_record(path, planar2);
    fuzz::require(record.t.allFinite() && record.q.allFinite() && record.tau.allFinite(),
                  "read_joint_record returns finite samples");
    // The one-joint experiment path (identify --model decoupled, issue 27 item 6): a run that
    // preprocess() accepts gives a finite fit or a dynid::Error, never NaN.
    SignalOptions signal;
    signal.filter = false;
    std::vector<std::pair<std::string, std::string>> choices;
    const std::vector<ProcessedRecord> runs = {preprocess(record, signal, choices)};
    const DecoupledJointResult fit = fit_decoupled_joint(runs, 0);
    fuzz::require(fit.estimate.x.allFinite(), "an accepted one-joint experiment is finite");
    // The temporary-file path: outputs of a batch that is never committed leave nothing.
    const std::string out = path + ".result.json";
    {
      OutputBatch batch;
      write_json(out, nlohmann::json{{"relative_error", json_number(fit.relative_error)}});
    }
    fuzz::require(temporary_files_in_flight() == 0, "an abandoned batch removes its files");
    fuzz::require(!std::ifstream(out), "an abandoned batch renames nothing");
  });
  return 0;
}
