#include "dynid/io/csv_chunk_reader.hpp"

#include <algorithm>
#include <cerrno>
#include <cstring>

#include "dynid/common/error.hpp"
#include "dynid/io/csv_reader.hpp"
#include "io/csv_parse.hpp"

namespace dynid {

namespace {
// Text bytes after which next_text ends a chunk early (the 29-column runs of 10⁶ samples have
// 2.3 MB chunks of 4096 lines).
constexpr std::size_t kMaxChunkText = std::size_t{16} << 20;
}  // namespace

struct CsvChunkReader::Impl {
  std::string source;
  CsvChunkOptions options;
  std::FILE* file = nullptr;
  std::vector<char> buffer;
  std::size_t pos = 0;     // start of unread text in buffer
  std::size_t filled = 0;  // end of valid text in buffer
  bool eof = false;
  // Line terminator (csv_detail::detect_eol), 0 until the file's first line end has been read:
  // it may lie beyond the first buffer, and the in-memory reader decides on the same line end.
  char eol = 0;
  long line = 0;
  Eigen::Index rows = 0;
  std::vector<std::string> columns;
  CsvTextChunk chunk;  // next()'s text, reused

  ~Impl() {
    if (file != nullptr) std::fclose(file);
  }

  // Next line as [b, e) without CR/LF. Returns false at the end of the file.
  bool next_line(const char*& b, const char*& e, bool& terminated) {
    while (true) {
      char* start = buffer.data() + pos;
      const std::size_t avail = filled - pos;
      if (eol == 0) {
        const char* end = start + avail;
        const char* p = start;
        while (p < end && *p != '\n' && *p != '\r') ++p;
        // A CR at the end of the buffer may be the first half of a CRLF: read on to decide.
        if (p < end && (*p == '\n' || p + 1 < end || eof)) eol = csv_detail::detect_eol(start, end);
      }
      char* nl = eol == 0 ? nullptr : static_cast<char*>(std::memchr(start, eol, avail));
      if (static_cast<std::size_t>(
              (nl != nullptr ? nl - start : static_cast<std::ptrdiff_t>(avail))) >
          kMaxCsvLineBytes) {
        csv_detail::throw_long_line(source, line + 1);
      }
      if (nl != nullptr) {
        b = start;
        e = csv_detail::strip_cr(b, nl);
        terminated = true;
        pos += static_cast<std::size_t>(nl - start) + 1;
        ++line;
        return true;
      }
      if (eof) {
        if (avail == 0) return false;
        b = start;
        e = csv_detail::strip_cr(b, start + avail);
        terminated = false;
        pos = filled;
        ++line;
        return true;
      }
      // Keep the partial line, then read more (grow only for a line longer than the buffer).
      std::memmove(buffer.data(), start, avail);
      pos = 0;
      filled = avail;
      if (filled == buffer.size()) buffer.resize(std::min(buffer.size() * 2, kMaxCsvLineBytes + 2));
      const std::size_t got = std::fread(buffer.data() + filled, 1, buffer.size() - filled, file);
      filled += got;
      if (got == 0) {
        if (std::ferror(file)) {
          throw Error(source + ": read error (" + std::strerror(errno) + "); check the file");
        }
        eof = true;
      }
    }
  }
};

CsvChunkReader::CsvChunkReader(const std::string& path, const CsvChunkOptions& options)
    : impl_(std::make_unique<Impl>()) {
  if (options.chunk_rows < 1) {
    throw Error("CsvChunkOptions::chunk_rows is " + std::to_string(options.chunk_rows) +
                "; use a positive number of rows");
  }
  impl_->source = path;
  impl_->options = options;
  impl_->buffer.resize(std::max<std::size_t>(options.buffer_bytes, 64));
  impl_->file = std::fopen(path.c_str(), "rb");
  if (impl_->file == nullptr) {
    throw Error(path + ": cannot open (" + std::strerror(errno) +
                "); check the path given to --in");
  }
  // First read: skip a byte-order mark (the line terminator is learnt by next_line).
  Impl& s = *impl_;
  s.filled = std::fread(s.buffer.data(), 1, s.buffer.size(), s.file);
  if (s.filled < s.buffer.size()) {
    if (std::ferror(s.file)) {
      throw Error(path + ": read error (" + std::strerror(errno) + "); check the file");
    }
    s.eof = true;
  }
  s.pos = csv_detail::bom_length(s.buffer.data(), s.buffer.data() + s.filled);
  const char* b = nullptr;
  const char* e = nullptr;
  bool terminated = true;
  while (impl_->next_line(b, e, terminated)) {
    if (csv_detail::is_skippable(b, e)) continue;
    impl_->columns = csv_detail::parse_header(b, e, path, impl_->line);
    return;
  }
  csv_detail::throw_empty(path);
}

CsvChunkReader::~CsvChunkReader() = default;

const std::vector<std::string>& CsvChunkReader::columns() const {
  return impl_->columns;
}

Eigen::Index CsvChunkReader::rows_read() const {
  return impl_->rows;
}

bool CsvChunkReader::next(Eigen::MatrixXd& block) {
  if (!next_text(impl_->chunk)) {
    block.resize(0, static_cast<Eigen::Index>(impl_->columns.size()));
    return false;
  }
  parse_text(impl_->chunk, block);
  return true;
}

bool CsvChunkReader::next_text(CsvTextChunk& chunk) {
  Impl& s = *impl_;
  chunk.text.clear();
  chunk.ends.clear();
  chunk.lines.clear();
  chunk.first_row = s.rows;
  chunk.unterminated = false;
  const char* b = nullptr;
  const char* e = nullptr;
  bool terminated = true;
  try {
    // A chunk also ends after kMaxChunkText bytes, so that chunks of very wide rows (up to 1 MiB
    // each) queued between threads stay bounded in memory.
    while (chunk.rows() < s.options.chunk_rows && chunk.text.size() < kMaxChunkText &&
           s.next_line(b, e, terminated)) {
      if (csv_detail::is_skippable(b, e)) continue;
      chunk.text.insert(chunk.text.end(), b, e);
      chunk.ends.push_back(chunk.text.size());
      chunk.lines.push_back(s.line);
      chunk.unterminated = !terminated;
    }
  } catch (const Error&) {
    // The first error in file order wins, as in a row-by-row read: a malformed row cut before
    // the failing read (or over-long line) is reported instead.
    Eigen::MatrixXd rows_before;
    parse_text(chunk, rows_before);
    throw;
  }
  s.rows += chunk.rows();
  if (chunk.rows() == 0 && s.rows == 0) {
    throw Error(s.source + ": header but no data rows; add one line of numbers per sample");
  }
  return chunk.rows() > 0;
}

void CsvChunkReader::parse_into(const CsvTextChunk& chunk, double* out, Eigen::Index row_step,
                                Eigen::Index column_step) const {
  const Impl& s = *impl_;
  const Eigen::Index rows = chunk.rows();
  const char* text = chunk.text.data();
  for (Eigen::Index k = 0; k < rows; ++k) {
    const std::size_t begin = k == 0 ? 0 : chunk.ends[static_cast<std::size_t>(k - 1)];
    const std::size_t end = chunk.ends[static_cast<std::size_t>(k)];
    csv_detail::parse_row(text + begin, text + end, s.columns, out + k * row_step, column_step,
                          s.source, chunk.lines[static_cast<std::size_t>(k)],
                          static_cast<long>(chunk.first_row + k) + 1,
                          chunk.unterminated && k + 1 == rows);
  }
}

void CsvChunkReader::parse_text(const CsvTextChunk& chunk, Eigen::MatrixXd& block) const {
  block.resize(chunk.rows(), static_cast<Eigen::Index>(impl_->columns.size()));
  parse_into(chunk, block.data(), 1, block.rows());
}

void CsvChunkReader::parse_text(const CsvTextChunk& chunk, RowBlock& block) const {
  block.resize(chunk.rows(), static_cast<Eigen::Index>(impl_->columns.size()));
  parse_into(chunk, block.data(), block.cols(), 1);
}

void for_each_csv_chunk(
    const std::string& path,
    const std::function<void(const std::vector<std::string>& columns, const Eigen::MatrixXd& block,
                             Eigen::Index first_row)>& callback,
    const CsvChunkOptions& options) {
  CsvChunkReader reader(path, options);
  Eigen::MatrixXd block(options.chunk_rows, static_cast<Eigen::Index>(reader.columns().size()));
  Eigen::Index first = 0;
  while (reader.next(block)) {
    callback(reader.columns(), block, first);
    first = reader.rows_read();
  }
}

}  // namespace dynid
