#include "dynid/io/csv_chunk_reader.hpp"

#include <random>
#include <thread>

#include <gtest/gtest.h>

#include "dynid/io/csv_reader.hpp"
#include "dynid/io/csv_writer.hpp"
#include "io/io_test_support.hpp"

namespace dynid {
namespace {

using test::error_of;
using test::TempDir;

// Oracle: read_csv of the same file (itself checked against literals in csv_reader_test).
TEST(CsvChunkReader, BlocksConcatenateToTheWholeFileForAnyChunkAndBufferSize) {
  TempDir dir;
  std::mt19937 rng(7);
  std::normal_distribution<double> normal;
  Eigen::MatrixXd data(1001, 3);
  for (Eigen::Index i = 0; i < data.size(); ++i) data.data()[i] = normal(rng);
  std::string text = "# comment\r\n" + format_csv({"t", "q1", "dq1"}, data);
  // Comments and CRLF in the middle; a complete last line without newline.
  text.insert(text.find('\n', 200) + 1, "# mid comment\n\n");
  text.pop_back();
  const std::string path = dir.write("big.csv", text);
  const CsvTable whole = read_csv(path);
  ASSERT_EQ(whole.rows(), 1001);
  ASSERT_EQ(whole.data, data);
  for (const Eigen::Index chunk : {1, 3, 64, 1000, 5000}) {
    for (const std::size_t buffer : {std::size_t{16}, std::size_t{97}, std::size_t{1} << 20}) {
      CsvChunkReader reader(path, {chunk, buffer});
      EXPECT_EQ(reader.columns(), whole.columns);
      Eigen::MatrixXd block;
      Eigen::Index row = 0;
      while (reader.next(block)) {
        ASSERT_LE(block.rows(), chunk);
        ASSERT_EQ(block, whole.data.middleRows(row, block.rows())) << chunk << " " << buffer;
        row += block.rows();
      }
      EXPECT_EQ(row, 1001);
      EXPECT_EQ(reader.rows_read(), 1001);
    }
  }
  Eigen::Index seen = 0;
  for_each_csv_chunk(path,
                     [&](const std::vector<std::string>& columns, const Eigen::MatrixXd& block,
                         Eigen::Index first) {
                       EXPECT_EQ(columns.size(), 3u);
                       EXPECT_EQ(first, seen);
                       EXPECT_EQ(block, whole.data.middleRows(first, block.rows()));
                       seen += block.rows();
                     },
                     {100, 4096});
  EXPECT_EQ(seen, 1001);
}

TEST(CsvChunkReader, ErrorsNameFileAndLine) {
  TempDir dir;
  EXPECT_HAS(error_of([&] { CsvChunkReader r(dir.file("none.csv")); }), "none.csv: cannot open");
  EXPECT_HAS(error_of([&] { CsvChunkReader r(dir.write("e.csv", "\n# x\n")); }),
             "e.csv: file is empty");
  EXPECT_HAS(error_of([&] { CsvChunkReader r(dir.write("d.csv", "a,a\n1,2\n")); }),
             "d.csv:1: duplicate column name 'a'");
  const std::string bad = dir.write("bad.csv", "a,b\n1,2\n3,4\n5,nan\n7,8\n");
  CsvChunkReader reader(bad, {2, 16});
  Eigen::MatrixXd block;
  ASSERT_TRUE(reader.next(block));
  EXPECT_HAS(error_of([&] { reader.next(block); }),
             "bad.csv:4: column 'b' (field 2) of data row 3 is NaN");
  CsvChunkReader truncated(dir.write("t.csv", "a,b\n1,2\n3"), {10, 16});
  EXPECT_HAS(error_of([&] { truncated.next(block); }), "t.csv:3: truncated last line");
}

// Issue 10: BOM, CR-only line ends and /dev/zero, for the streaming reader too.
TEST(CsvChunkReader, ByteOrderMarkCrOnlyAndLineLimit) {
  TempDir dir;
  CsvChunkOptions options;
  options.chunk_rows = 2;
  options.buffer_bytes = 64;  // lines cross buffer refills
  CsvChunkReader bom(dir.write("bom.csv", "\xEF\xBB\xBFt,q1\n0,1\n0.1,2\n0.2,3\n"), options);
  EXPECT_EQ(bom.columns(), (std::vector<std::string>{"t", "q1"}));
  std::string mac_text = "t,q1\r";
  for (int k = 0; k < 40; ++k) mac_text += std::to_string(k) + ",1.5\r";
  CsvChunkReader mac(dir.write("mac.csv", mac_text), options);
  EXPECT_EQ(mac.columns(), (std::vector<std::string>{"t", "q1"}));
  Eigen::MatrixXd block;
  Eigen::Index rows = 0;
  double last_t = -1.0;
  while (mac.next(block)) {
    rows += block.rows();
    last_t = block(block.rows() - 1, 0);
  }
  EXPECT_EQ(rows, 40);
  EXPECT_EQ(last_t, 39.0);
  const std::string m = error_of([] { CsvChunkReader zero("/dev/zero"); });
  EXPECT_HAS(m, "CSV file '/dev/zero' is not a regular file (a device)");  // issue 27 item 4
}

// Found by fuzz/csv_fuzzer: the streaming reader learnt the line terminator from its first buffer
// only, so a CR-only file whose first line end lies beyond it was read as one line, while
// read_csv() (the oracle here) saw 3 rows. Same terminator, same table, any buffer size.
TEST(CsvChunkReader, LineEndBeyondTheFirstBufferIsTheOneReadCsvSees) {
  TempDir dir;
  const std::string header = "t," + std::string(100, 'q') + "1";
  for (const std::string eol : {"\r", "\r\n", "\n"}) {
    const std::string path =
        dir.write("late.csv", header + eol + "0,1" + eol + "0.5,2" + eol + "1,3" + eol);
    const CsvTable table = read_csv(path);
    for (const std::size_t bytes : {std::size_t{64}, header.size(), header.size() + 1}) {
      CsvChunkOptions options;
      options.buffer_bytes = bytes;  // the first buffer ends before, on or after the first CR
      CsvChunkReader reader(path, options);
      EXPECT_EQ(reader.columns(), table.columns) << bytes;
      Eigen::MatrixXd block, all(0, 2);
      while (reader.next(block)) {
        all.conservativeResize(all.rows() + block.rows(), 2);
        all.bottomRows(block.rows()) = block;
      }
      EXPECT_EQ(all, table.data) << "buffer " << bytes << " bytes, eol " << eol.size();
    }
  }
}

// Issue 16: the streaming identification cuts chunks on the reader thread and parses them on
// the workers. Oracle: read_csv of the same file; the chunks are parsed on other threads, out of
// order, and must give the same rows, row numbers and first error as next().
TEST(CsvChunkReader, TextChunksParsedOnOtherThreadsEqualTheWholeFile) {
  TempDir dir;
  std::mt19937 rng(16);
  std::normal_distribution<double> normal;
  Eigen::MatrixXd data(700, 4);
  for (Eigen::Index i = 0; i < data.size(); ++i) data.data()[i] = normal(rng);
  std::string text = format_csv({"t", "q1", "dq1", "tau1"}, data);
  text.insert(text.find('\n', 3000) + 1, "# mid comment\r\n\n");
  text.pop_back();  // the last line has no newline
  const std::string path = dir.write("chunks.csv", text);
  const CsvTable whole = read_csv(path);
  ASSERT_EQ(whole.data, data);
  CsvChunkReader reader(path, {64, 97});
  std::vector<CsvTextChunk> chunks;
  CsvTextChunk chunk;
  while (reader.next_text(chunk)) chunks.push_back(chunk);
  ASSERT_EQ(chunks.size(), 11u);  // 10 × 64 + 60
  std::vector<Eigen::MatrixXd> blocks(chunks.size());
  std::vector<std::thread> threads;
  for (std::size_t c = chunks.size(); c-- > 0;) {  // last chunk first
    threads.emplace_back([&, c] { reader.parse_text(chunks[c], blocks[c]); });
  }
  for (auto& t : threads) t.join();
  Eigen::Index row = 0;
  for (std::size_t c = 0; c < chunks.size(); ++c) {
    EXPECT_EQ(chunks[c].first_row, row);
    ASSERT_EQ(blocks[c], whole.data.middleRows(row, blocks[c].rows())) << "chunk " << c;
    row += blocks[c].rows();
  }
  EXPECT_EQ(row, 700);
  EXPECT_TRUE(chunks.back().unterminated);
  // Wide rows: a chunk ends once it holds 16 MiB of text (20 lines of 1.02 MB: 17 + 3 lines), so
  // the chunks queued between threads stay bounded; the rows are still those of read_csv.
  {
    std::string wide = "c0";
    for (int c = 1; c < 60000; ++c) wide += ",c" + std::to_string(c);
    wide += "\n";
    std::string line = "0.12345678901234";
    for (int c = 1; c < 60000; ++c) line += ",0.12345678901234";
    line += "\n";
    for (int r = 0; r < 20; ++r) wide += line;
    const std::string big = dir.write("wide.csv", wide);
    CsvChunkReader wide_reader(big, {4096, 1 << 20});
    std::vector<Eigen::Index> sizes;
    Eigen::MatrixXd parsed;
    while (wide_reader.next_text(chunk)) {
      sizes.push_back(chunk.rows());
      wide_reader.parse_text(chunk, parsed);
      EXPECT_TRUE((parsed.array() == 0.12345678901234).all());
    }
    EXPECT_EQ(sizes, (std::vector<Eigen::Index>{17, 3}));
  }
  // A malformed row cut before an over-long line of the same chunk is the error reported, as a
  // row-by-row read finds it first; on its own chunk, the bad field names its file line.
  const std::string bad = dir.write(
      "order.csv", "a,b\n1,2\n3,x\n4,5\n" + std::string(kMaxCsvLineBytes + 10, '7') + "\n");
  CsvChunkReader first(bad, {100, 1 << 20});
  EXPECT_HAS(error_of([&] { first.next_text(chunk); }), "order.csv:3: column 'b' (field 2)");
  CsvChunkReader alone(bad, {1, 1 << 20});
  ASSERT_TRUE(alone.next_text(chunk));
  ASSERT_TRUE(alone.next_text(chunk));
  Eigen::MatrixXd block;
  EXPECT_HAS(error_of([&] { alone.parse_text(chunk, block); }), "order.csv:3: column 'b'");
  EXPECT_TRUE(alone.next_text(chunk));
  EXPECT_HAS(error_of([&] { alone.next_text(chunk); }), "order.csv:5: line is longer than");
}

// Issue 16: CsvBlockReader cuts the file into byte blocks parsed by several threads at once.
// Parses every block, block b on thread b mod `threads`, and concatenates the rows in block order.
struct BlockRead {
  Eigen::MatrixXd rows;
  std::vector<std::uint64_t> offsets;
};
BlockRead read_blocks(const std::string& path, std::size_t block_bytes, int threads) {
  const CsvBlockReader reader(path, {block_bytes});
  std::vector<CsvBlock> blocks(static_cast<std::size_t>(reader.blocks()));
  std::vector<std::thread> pool;
  for (int t = 0; t < threads; ++t) {
    pool.emplace_back([&, t] {
      for (std::size_t b = t; b < blocks.size(); b += threads) reader.parse(b, blocks[b]);
    });
  }
  for (auto& t : pool) t.join();
  BlockRead all;
  all.rows.resize(0, static_cast<Eigen::Index>(reader.columns().size()));
  for (const CsvBlock& block : blocks) {
    all.rows.conservativeResize(all.rows.rows() + block.rows.rows(), Eigen::NoChange);
    all.rows.bottomRows(block.rows.rows()) = block.rows;
    all.offsets.insert(all.offsets.end(), block.offsets.begin(), block.offsets.end());
  }
  return all;
}

// Oracle: read_csv of the same file. Block sizes from 1 byte (most blocks hold no line start) to
// larger than the file, with a line exactly on a block boundary, CRLF and CR-only line ends,
// comments and blank lines before the header and in the middle, no final newline; 1-3 threads.
TEST(CsvBlockReader, BlocksInAnyThreadCountConcatenateToReadCsv) {
  TempDir dir;
  std::mt19937 rng(161);
  std::normal_distribution<double> normal;
  Eigen::MatrixXd data(150, 4);
  for (Eigen::Index i = 0; i < data.size(); ++i) data.data()[i] = normal(rng);
  std::string lf = "# comment\n" + format_csv({"t", "q1", "dq1", "tau1"}, data);
  lf.insert(lf.find('\n', 3000) + 1, "# mid comment\n\n  \n");
  lf.pop_back();  // no final newline
  std::string crlf, cr;
  for (char c : lf) {
    crlf += c == '\n' ? std::string("\r\n") : std::string(1, c);
    cr += c == '\n' ? '\r' : c;
  }
  // Lines of 16 bytes after a 5-byte header: blocks of 16 bytes start exactly on a line.
  std::string fixed = "t,q1\n";
  Eigen::MatrixXd fixed_data(40, 2);
  for (int k = 0; k < 40; ++k) {
    char line[32];
    std::snprintf(line, sizeof line, "%07d,%07d\n", k, 2 * k);
    fixed += line;
    fixed_data.row(k) << k, 2 * k;
  }
  struct Case {
    std::string name, text;
    std::vector<std::size_t> block_bytes;
  };
  const std::vector<Case> cases = {{"lf.csv", lf, {1, 2, 7, 97, 1000, 1 << 20}},
                                   {"crlf.csv", crlf, {1, 3, 61, 4096}},
                                   {"cr.csv", cr, {1, 5, 333}},
                                   {"fixed.csv", fixed, {1, 8, 15, 16, 17, 32}}};
  for (const Case& c : cases) {
    const std::string path = dir.write(c.name, c.text);
    const CsvTable whole = read_csv(path);
    ASSERT_EQ(whole.data, c.name == "fixed.csv" ? fixed_data : data) << c.name;
    for (const std::size_t bytes : c.block_bytes) {
      for (int threads = 1; threads <= 3; ++threads) {
        const BlockRead r = read_blocks(path, bytes, threads);
        ASSERT_EQ(r.rows, whole.data) << c.name << " " << bytes << " bytes " << threads;
        // Each row's offset is the start of its line: after a line end.
        ASSERT_EQ(r.offsets.size(), static_cast<std::size_t>(whole.rows()));
        for (std::size_t k = 0; k < r.offsets.size(); ++k) {
          ASSERT_TRUE(c.text[r.offsets[k] - 1] == (c.name == "cr.csv" ? '\r' : '\n'))
              << c.name << " row " << k;
        }
      }
    }
  }
  const CsvBlockReader reader(dir.file("fixed.csv"), {16});
  EXPECT_EQ(reader.columns(), (std::vector<std::string>{"t", "q1"}));
  EXPECT_EQ(reader.blocks(), 40);
  EXPECT_EQ(reader.block_begin(0), 5u);
  EXPECT_EQ(reader.block_begin(40), reader.file_bytes());
  EXPECT_EQ(reader.position(5 + 16 * 7).line, 9);  // header on line 1, data row 8
  EXPECT_EQ(reader.position(5 + 16 * 7).row, 8);
}

// The first error of a sequential read over the blocks is CsvChunkReader's, word for word,
// wherever the faulty line lies: the first data line, a line in the middle (after comments), a
// truncated last line, an over-long line; block.error_offset is the start of that line.
TEST(CsvBlockReader, ErrorsNameTheLineInEveryBlockPosition) {
  TempDir dir;
  std::string good = "# c\na,b\n";
  for (int k = 0; k < 60; ++k) {
    good += std::to_string(k) + ".25,-" + std::to_string(3 * k) + ".5\n";
    if (k == 20) good += "# mid\n\n";
  }
  const auto line_start = [&](const std::string& text, int line) {
    std::size_t pos = 0;
    for (int l = 1; l < line; ++l) pos = text.find('\n', pos) + 1;
    return pos;
  };
  const auto replace_line = [&](int line, const std::string& with, std::string text = {}) {
    if (text.empty()) text = good;
    const std::size_t b = line_start(text, line);
    text.replace(b, text.find('\n', b) - b, with);
    return text;
  };
  std::string truncated = good;
  truncated.resize(truncated.size() - 8);  // "59.25,-177.5\n" cut to "59.25"
  std::string crlf_bad;
  for (char c : replace_line(40, "1,2,3"))
    crlf_bad += c == '\n' ? std::string("\r\n") : std::string(1, c);
  const std::vector<std::pair<std::string, std::string>> files = {
      {"first.csv", replace_line(3, "0.25,x")},
      {"middle.csv", replace_line(37, "nan,1")},
      {"crlf.csv", crlf_bad},
      {"last.csv", truncated},
      {"long.csv", replace_line(50, std::string(kMaxCsvLineBytes + 1, '1'))},
      {"two.csv", replace_line(45, "1,,2", replace_line(12, "1;2"))}};
  for (const auto& [name, text] : files) {
    const std::string path = dir.write(name, text);
    CsvChunkReader sequential(path, {7, 1 << 20});
    Eigen::MatrixXd rows;
    const std::string expected = error_of([&] {
      while (sequential.next(rows)) {
      }
    });
    EXPECT_HAS(expected, name + ":");
    for (const std::size_t bytes :
         {std::size_t{1}, std::size_t{13}, std::size_t{200}, std::size_t{1} << 21}) {
      const CsvBlockReader reader(path, {bytes});
      CsvBlock block;
      std::string message;
      for (std::int64_t b = 0; b < reader.blocks() && message.empty(); ++b) {
        try {
          reader.parse(b, block);
        } catch (const Error& e) {
          message = e.what();
          const std::uint64_t at = block.error_offset;
          EXPECT_TRUE(at == reader.block_begin(0) || text[at - 1] == '\n') << name << " " << at;
          EXPECT_EQ(reader.position(at).line,
                    1 + std::count(text.begin(), text.begin() + at, '\n'));
        }
      }
      EXPECT_EQ(message, expected) << name << ", blocks of " << bytes << " bytes";
    }
  }
  const std::string header_only = dir.write("h.csv", "a,b\n# only\n");
  EXPECT_EQ(error_of([&] { CsvBlockReader r(header_only); }), error_of([&] {
              CsvChunkReader r(header_only);
              Eigen::MatrixXd rows;
              r.next(rows);
            }));
  EXPECT_HAS(error_of([&] { CsvBlockReader r(dir.write("z.csv", "a,b\n1,2\n"), {0}); }),
             "block_bytes is 0");
}

}  // namespace
}  // namespace dynid
