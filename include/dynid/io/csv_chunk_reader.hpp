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

  /// Number of data rows yielded so far.
  Eigen::Index rows_read() const;

 private:
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
