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
  EXPECT_HAS(m, "/dev/zero:1: line is longer than 1 MiB");
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

}  // namespace
}  // namespace dynid
