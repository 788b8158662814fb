#pragma once

#include <cstdint>
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
  friend class CsvBlockReader;  // reads the header with this class's rules and keeps its offset
};

/// Options of CsvBlockReader.
struct CsvBlockOptions {
  /// Bytes of the file per block (> 0). About a core's L2 cache, so that the thread that reads a
  /// block parses text still in its own cache.
  std::size_t block_bytes = std::size_t{256} << 10;
};

/// A block parsed by CsvBlockReader::parse, and the parsing thread's scratch (storage is reused).
struct CsvBlock {
  CsvChunkReader::RowBlock rows;       ///< data rows × columns, a sample's fields contiguous
  std::vector<std::uint64_t> offsets;  ///< offsets[k]: file byte offset where row k's line starts
  /// After parse threw: the byte offset of the failing line (for ordering errors across blocks).
  std::uint64_t error_offset = 0;
  std::vector<char> text;  ///< scratch: the block's bytes and the rest of its last line
  struct Line {
    std::size_t begin, end;  // in text, without the terminator (and CR)
    bool data;               // not blank, not a comment
    bool terminated;         // false only for the file's last line without a final newline
  };
  std::vector<Line> lines;  ///< scratch: every line starting in the block
};

/// 1-based file line and data row (comments and blank lines not counted) of a line.
struct CsvPosition {
  long line = 0;  ///< file line
  long row = 0;   ///< data row
};

/// Random-access CSV reader for parallel parsing (identify_stream): the bytes after the header are
/// cut into blocks of options.block_bytes, and block b holds the lines that START in it (it reads
/// past its end to finish the last one), so blocks 0, 1, … concatenated give read_csv's rows for
/// any block size. parse() may be called from several threads at once, each with its own CsvBlock
/// (pread on one descriptor): each thread reads and parses its own text. Same format and errors as
/// CsvChunkReader; since a block does not know its first line number, the number in a message is
/// found when a line fails, by counting the line ends before it (an error costs a read of the file
/// up to the failing line). Regular files only. Memory: one block (plus one line) per thread.
class CsvBlockReader {
 public:
  /// Opens `path` and reads its header. Throws dynid::Error as CsvChunkReader does, for a file
  /// with a header but no data rows, for a file that is not a regular file and for a block size
  /// of 0.
  explicit CsvBlockReader(const std::string& path, const CsvBlockOptions& options = {});
  ~CsvBlockReader();
  CsvBlockReader(const CsvBlockReader&) = delete;
  CsvBlockReader& operator=(const CsvBlockReader&) = delete;

  /// Header names in file order.
  const std::vector<std::string>& columns() const;
  /// Number of blocks (≥ 1).
  std::int64_t blocks() const;
  /// File byte offset of block b's first byte (b in [0, blocks()]; blocks() gives the file size).
  std::uint64_t block_begin(std::int64_t b) const;
  /// File size in bytes.
  std::uint64_t file_bytes() const;

  /// Reads and parses block b (0 ≤ b < blocks()) into block.rows and block.offsets (possibly no
  /// rows: a block inside one long line). Throws dynid::Error for malformed rows and over-long
  /// lines (file, line, column, fix) and for read errors; block.error_offset then holds the start
  /// of the failing line.
  void parse(std::int64_t b, CsvBlock& block) const;

  /// Line and data row of the line starting at byte `offset` (a value of CsvBlock::offsets or
  /// error_offset), by counting the lines before it: for messages, not for a hot path.
  CsvPosition position(std::uint64_t offset) const;

 private:
  // Cuts the lines of block b that start before `stop` into block.lines (block.text holds them).
  // Throws for over-long lines and read errors, with block.error_offset set.
  void cut(std::int64_t b, CsvBlock& block, std::uint64_t stop) const;
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
