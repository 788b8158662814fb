#include "dynid/io/csv_chunk_reader.hpp"

#include <algorithm>
#include <cerrno>
#include <cstring>

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include "dynid/common/error.hpp"
#include "dynid/common/input_file.hpp"
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
  std::size_t pos = 0;              // start of unread text in buffer
  std::size_t filled = 0;           // end of valid text in buffer
  std::uint64_t buffer_offset = 0;  // file offset of buffer[0]
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
      buffer_offset += pos;
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
  require_regular_file(path, "CSV file");
  impl_->file = std::fopen(path.c_str(), "rb");
  if (impl_->file == nullptr) {
    throw Error(path + ": cannot open (" + std::strerror(errno) +
                "); check the path and that the file is readable");
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

struct CsvBlockReader::Impl {
  std::string source;
  std::size_t block_bytes = 0;
  int fd = -1;
  std::uint64_t size = 0;
  std::uint64_t data = 0;  // offset of the first byte after the header line
  long header_line = 0;
  char eol = '\n';
  std::vector<std::string> columns;
  ~Impl() {
    if (fd >= 0) ::close(fd);
  }
  // Appends the file's bytes [from, to) to text; fewer at the end of the file.
  void read(std::uint64_t from, std::uint64_t to, std::vector<char>& text) const {
    std::size_t at = text.size();
    text.resize(at + static_cast<std::size_t>(to - from));
    while (from < to) {
      const ssize_t got = ::pread(fd, text.data() + at, static_cast<std::size_t>(to - from),
                                  static_cast<off_t>(from));
      if (got < 0) {
        if (errno == EINTR) continue;
        throw Error(source + ": read error (" + std::strerror(errno) + "); check the file");
      }
      if (got == 0) break;  // the file shrank: what is there is all there is
      from += static_cast<std::uint64_t>(got);
      at += static_cast<std::size_t>(got);
    }
    text.resize(at);
  }
};

CsvBlockReader::CsvBlockReader(const std::string& path, const CsvBlockOptions& options)
    : impl_(std::make_unique<Impl>()) {
  Impl& s = *impl_;
  s.source = path;
  if (options.block_bytes == 0) {
    throw Error("CsvBlockOptions::block_bytes is 0; use a positive number of bytes");
  }
  s.block_bytes = options.block_bytes;
  {
    // The header and the data rows' first line with the sequential reader's rules (byte-order
    // mark, comments, line terminator, "header but no data rows").
    CsvChunkReader header(path, {1, std::size_t{1} << 16});
    const CsvChunkReader::Impl& h = *header.impl_;
    s.data = h.buffer_offset + h.pos;
    s.header_line = h.line;
    s.eol = h.eol;
    s.columns = h.columns;
    CsvTextChunk first;
    header.next_text(first);
  }
  s.fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  struct stat st {};
  if (s.fd < 0 || ::fstat(s.fd, &st) != 0) {
    throw Error(path + ": cannot open (" + std::strerror(errno) +
                "); check the path and that the file is readable");
  }
  if (!S_ISREG(st.st_mode)) {
    throw Error(path + ": not a regular file; give the path of a CSV file");
  }
  s.size = static_cast<std::uint64_t>(st.st_size);
}

CsvBlockReader::~CsvBlockReader() = default;

const std::vector<std::string>& CsvBlockReader::columns() const {
  return impl_->columns;
}

std::int64_t CsvBlockReader::blocks() const {
  const Impl& s = *impl_;
  return static_cast<std::int64_t>((s.size - std::min(s.data, s.size) + s.block_bytes - 1) /
                                   s.block_bytes);
}

std::uint64_t CsvBlockReader::block_begin(std::int64_t b) const {
  const Impl& s = *impl_;
  return std::min(s.size, s.data + static_cast<std::uint64_t>(b) * s.block_bytes);
}

std::uint64_t CsvBlockReader::file_bytes() const {
  return impl_->size;
}

void CsvBlockReader::cut(std::int64_t b, CsvBlock& block, std::uint64_t stop) const {
  const Impl& s = *impl_;
  const std::uint64_t begin = block_begin(b);
  const std::uint64_t end = std::min(block_begin(b + 1), stop);
  block.error_offset = begin;
  block.lines.clear();
  block.text.clear();
  if (begin >= end) return;
  // From one byte before the block: a line starts at the block's first byte if that one is a line
  // end. text[i] is the file's byte from + i.
  const std::uint64_t from = b == 0 ? begin : begin - 1;
  s.read(from, block_begin(b + 1), block.text);
  std::size_t p = 0;
  if (b > 0) {
    const void* nl = std::memchr(block.text.data(), s.eol, block.text.size());
    if (nl == nullptr) return;  // inside a line that started before the block
    p = static_cast<std::size_t>(static_cast<const char*>(nl) - block.text.data()) + 1;
  }
  const std::size_t limit = static_cast<std::size_t>(end - from);
  std::size_t searched = p;  // no line end in text[p, searched)
  while (p < std::min(limit, block.text.size())) {
    const void* found =
        std::memchr(block.text.data() + searched, s.eol, block.text.size() - searched);
    if (found == nullptr && block.text.size() - p <= kMaxCsvLineBytes &&
        from + block.text.size() < s.size) {
      // The last line goes on past the block: read more of it (doubling, so that a long line
      // costs linear time) up to the line-length limit.
      searched = block.text.size();
      const std::uint64_t more = std::max<std::uint64_t>(std::size_t{1} << 12, searched - p);
      s.read(from + searched, std::min(s.size, from + searched + more), block.text);
      if (block.text.size() > searched) continue;
      // Nothing more to read (the file shrank under us): what there is ends the file.
    }
    const char* text = block.text.data();
    const std::size_t nl = found != nullptr
                               ? static_cast<std::size_t>(static_cast<const char*>(found) - text)
                               : block.text.size();
    if (nl - p > kMaxCsvLineBytes) {
      block.error_offset = from + p;
      csv_detail::throw_long_line(s.source, position(from + p).line);
    }
    const char* e = csv_detail::strip_cr(text + p, text + nl);
    block.lines.push_back({p, static_cast<std::size_t>(e - text),
                           !csv_detail::is_skippable(text + p, e), found != nullptr});
    p = nl + 1;
    searched = p;
  }
}

void CsvBlockReader::parse(std::int64_t b, CsvBlock& block) const {
  const Impl& s = *impl_;
  cut(b, block, s.size);
  std::size_t rows = 0;
  for (const CsvBlock::Line& line : block.lines) rows += line.data;
  const auto columns = static_cast<Eigen::Index>(s.columns.size());
  block.rows.resize(static_cast<Eigen::Index>(rows), columns);
  block.offsets.resize(rows);
  const std::uint64_t from = b == 0 ? block_begin(b) : block_begin(b) - 1;
  const char* text = block.text.data();
  Eigen::Index k = 0;
  for (const CsvBlock::Line& line : block.lines) {
    if (!line.data) continue;
    const bool unterminated = !line.terminated;
    block.offsets[static_cast<std::size_t>(k)] = from + line.begin;
    double* out = block.rows.data() + k * columns;
    try {
      csv_detail::parse_row(text + line.begin, text + line.end, s.columns, out, 1, s.source, 0, 0,
                            unterminated);
    } catch (const Error&) {
      // Parse again with the line's numbers, now that they are needed: the same error, named.
      block.error_offset = from + line.begin;
      const CsvPosition at = position(block.error_offset);
      csv_detail::parse_row(text + line.begin, text + line.end, s.columns, out, 1, s.source,
                            at.line, at.row, unterminated);
      throw;
    }
    ++k;
  }
}

CsvPosition CsvBlockReader::position(std::uint64_t offset) const {
  const Impl& s = *impl_;
  CsvPosition at{s.header_line + 1, 1};
  CsvBlock scratch;
  for (std::int64_t b = 0; b < blocks() && block_begin(b) < offset; ++b) {
    cut(b, scratch, offset);
    at.line += static_cast<long>(scratch.lines.size());
    for (const CsvBlock::Line& line : scratch.lines) at.row += line.data;
  }
  return at;
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
