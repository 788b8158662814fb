#pragma once

#include <cstdio>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include <Eigen/Core>

namespace dynid {

/// Options of the streaming CSV reader.
struct CsvChunkOptions {
  Eigen::Index chunk_rows = 4096;      ///< maximum rows per block yielded by next()
  std::size_t buffer_bytes = 1 << 20;  ///< file read size; grows only if one line is longer
};

/// The unparsed text of up to chunk_rows data lines of a CSV file (comments and blank lines
/// dropped), cut by CsvChunkReader::next_text so that another thread can parse it with
/// CsvChunkReader::parse_text: splitting lines is cheap, parsing numbers is not.
struct CsvTextChunk {
  std::vector<char> text;         ///< the data lines back to back, without their terminators
  std::vector<std::size_t> ends;  ///< ends[k]: end of data line k in text (starts at ends[k−1], 0)
  std::vector<long> lines;        ///< 1-based file line of data line k (for messages)
  Eigen::Index first_row = 0;     ///< 0-based data-row index of the chunk's first line
  bool unterminated = false;      ///< the last line is the file's last and has no final newline
  /// Number of data lines in the chunk.
  Eigen::Index rows() const { return static_cast<Eigen::Index>(ends.size()); }
};

/// Streaming CSV reader with constant memory: reads the header on construction, then yields blocks
/// of at most chunk_rows rows. Same format and errors as read_csv (csv_reader.hpp); an error is
/// thrown by the next() call that reaches the faulty line. Use it for files too large to hold
/// (identification from 10⁶ samples). Not copyable.
class CsvChunkReader {
 public:
  /// Opens `path` and reads its header. Throws dynid::Error for a missing, empty or headerless file
  /// and for empty or duplicate column names.
  explicit CsvChunkReader(const std::string& path, const CsvChunkOptions& options = {});
  ~CsvChunkReader();
  CsvChunkReader(const CsvChunkReader&) = delete;
  CsvChunkReader& operator=(const CsvChunkReader&) = delete;

  /// Header names in file order.
  const std::vector<std::string>& columns() const;

  /// Reads the next rows into `block` (resized to rows × columns().size(), rows ≤ chunk_rows; the
  /// storage is reused while the size is unchanged). Returns false, with block left empty, once the
  /// file is exhausted. Throws dynid::Error for malformed rows (file, line, column, fix).
  bool next(Eigen::MatrixXd& block);

  /// next() in two halves, for a pipeline: next_text cuts the next rows (as next() would yield
  /// them: at most chunk_rows, fewer once the chunk holds 16 MiB of text) without parsing, reusing
  /// `chunk`'s storage. Returns false, with chunk empty, once the file is exhausted. Throws
  /// dynid::Error for read errors, over-long lines and a file with a header but no data rows;
  /// malformed numbers are found by parse_text.
  bool next_text(CsvTextChunk& chunk);

  /// Parses a chunk cut by next_text of this reader into `block` (resized to chunk.rows() ×
  /// columns().size()), with the errors of next() (file, line, column, fix). Reads only the
  /// header, so other threads may call it while next_text cuts the following chunks.
  void parse_text(const CsvTextChunk& chunk, Eigen::MatrixXd& block) const;

  /// Row-major block (chunk.rows() × columns().size()), sample k's fields contiguous: parse_text
  /// for a consumer that reads a whole sample at a time (identify_stream); the parse writes and
  /// the consumer reads memory in order instead of one cache line per column. Same errors.
  using RowBlock = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
  void parse_text(const CsvTextChunk& chunk, RowBlock& block) const;

  /// Number of data rows yielded so far.
  Eigen::Index rows_read() const;

 private:
  // Parses chunk row k, field c into out[k·row_step + c·column_step].
  void parse_into(const CsvTextChunk& chunk, double* out, Eigen::Index row_step,
                  Eigen::Index column_step) const;
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// Calls `callback(columns, block, first_row)` for every block of `path`, in file order;
/// first_row is the 0-based index of the block's first sample. Constant memory.
void for_each_csv_chunk(
    const std::string& path,
    const std::function<void(const std::vector<std::string>& columns, const Eigen::MatrixXd& block,
                             Eigen::Index first_row)>& callback,
    const CsvChunkOptions& options = {});

}  // namespace dynid
