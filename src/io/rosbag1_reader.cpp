// ROS 1 bags, format 2.0 (docs/methods/io.md "ROS logs"), read record by record with every
// length checked. Debian's rosbag_storage reads through the bag's index without checking its
// offsets (a flipped byte in a bag made it read out of bounds: 17 crashes in 600 mutated bags),
// so it only writes the tests' bags; here the records are scanned in file order, which also
// reads a bag whose recording was interrupted before the index was written.

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <map>
#include <memory>

#include <bzlib.h>
#include <lz4frame.h>

#include "dynid/common/error.hpp"
#include "dynid/common/input_file.hpp"
#include "dynid/common/message.hpp"
#include "io/joint_state_message.hpp"

namespace dynid::ros_detail {
namespace {

constexpr const char* kJointStateType = "sensor_msgs/JointState";
// The MD5 of the message definition: the same name with another layout would be misread.
constexpr const char* kJointStateMd5 = "3066dcd76a6cfaef579bd0f34173e9fd";
constexpr const char kMagic[] = "#ROSBAG V2.0\n";
// Record headers are a few fields (a connection's holds its message definition, a few kB).
constexpr std::size_t kMaxHeaderBytes = std::size_t{1} << 20;
// rosbag's chunks are 768 kB by default; a bigger threshold is a recording option.
constexpr std::size_t kMaxChunkBytes = std::size_t{1} << 28;

enum Op : std::uint8_t {
  kMessageData = 0x02,
  kBagHeader = 0x03,
  kIndexData = 0x04,
  kChunk = 0x05,
  kChunkInfo = 0x06,
  kConnection = 0x07
};

// Fields name=value of a record header (or of a connection's data).
using Fields = std::map<std::string, std::string>;

std::uint32_t le32(const std::uint8_t* p) {
  return static_cast<std::uint32_t>(p[0]) | static_cast<std::uint32_t>(p[1]) << 8 |
         static_cast<std::uint32_t>(p[2]) << 16 | static_cast<std::uint32_t>(p[3]) << 24;
}

class BagReader {
 public:
  BagReader(const std::string& path, const std::string& requested)
      : path_(path), requested_(requested) {}

  TopicMessages read() {
    require_regular_file(path_, "ROS bag");
    file_.reset(std::fopen(path_.c_str(), "rb"));
    if (!file_) {
      throw Error("ROS bag '" + path_ + "' cannot be opened (" + std::strerror(errno) +
                  "); check the path");
    }
    std::fseek(file_.get(), 0, SEEK_END);
    size_ = static_cast<std::uint64_t>(std::max(0L, std::ftell(file_.get())));
    std::fseek(file_.get(), 0, SEEK_SET);
    char magic[sizeof(kMagic) - 1] = {};
    if (std::fread(magic, 1, sizeof(magic), file_.get()) != sizeof(magic) ||
        std::memcmp(magic, kMagic, sizeof(magic)) != 0) {
      throw Error("'" + path_ + "' is not a ROS 1 bag (it does not start with '#ROSBAG V2.0'); " +
                  "give a bag recorded by rosbag (a ROS 2 bag is the .db3 in its folder)");
    }
    offset_ = sizeof(magic);
    std::vector<std::uint8_t> header, data;
    while (offset_ < size_) {
      const std::uint64_t start = offset_;
      if (!read_block(header, kMaxHeaderBytes, "record header")) break;
      const Fields fields = parse_fields(header.data(), header.size(), start);
      const std::uint8_t op = op_of(fields, start);
      // Connection and message records outside chunks: the index section repeats the
      // connections, and a recording stopped inside an uncompressed chunk leaves its records.
      if (op == kChunk || op == kConnection || op == kMessageData) {
        if (!read_block(data, kMaxChunkBytes, "record data")) break;
        if (op == kChunk) {
          read_chunk(fields, data, start);
        } else if (op == kConnection) {
          connection(fields, data.data(), data.size(), start);
        } else {
          message(fields, data.data(), data.size(), start);
        }
      } else if (!skip_block(start)) {
        break;
      }
    }
    return select();
  }

 private:
  struct FileCloser {
    void operator()(std::FILE* f) const { std::fclose(f); }
  };
  struct Connection {
    std::string topic, type, md5;
  };

  [[noreturn]] void corrupt(std::uint64_t at, const std::string& what) const {
    throw Error("ROS bag '" + path_ + "' is corrupt at byte " + std::to_string(at) + " (" + what +
                "); record it again, or check it with rosbag check");
  }

  // A uint32 length and that many bytes at the current offset; false when the file ends inside
  // it (an interrupted recording), which ends the scan with a warning.
  bool read_block(std::vector<std::uint8_t>& out, std::size_t cap, const char* what) {
    std::uint8_t n[4];
    if (size_ - offset_ < 4) return truncated();
    if (std::fread(n, 1, 4, file_.get()) != 4) return truncated();
    const std::uint32_t length = le32(n);
    if (length > cap)
      corrupt(offset_, std::string(what) + " of " + std::to_string(length) + " bytes");
    if (size_ - offset_ - 4 < length) return truncated();
    out.resize(length);
    if (length > 0 && std::fread(out.data(), 1, length, file_.get()) != length) return truncated();
    offset_ += 4 + length;
    return true;
  }
  bool skip_block(std::uint64_t start) {
    std::uint8_t n[4];
    if (size_ - offset_ < 4 || std::fread(n, 1, 4, file_.get()) != 4) return truncated();
    const std::uint32_t length = le32(n);
    if (size_ - offset_ - 4 < length) return truncated();
    if (std::fseek(file_.get(), static_cast<long>(length), SEEK_CUR) != 0) corrupt(start, "seek");
    offset_ += 4 + length;
    return true;
  }
  bool truncated() {
    truncated_at_ = offset_;
    return false;
  }

  Fields parse_fields(const std::uint8_t* p, std::size_t n, std::uint64_t at) const {
    Fields fields;
    std::size_t i = 0;
    while (i < n) {
      if (n - i < 4) corrupt(at, "a header field ends early");
      const std::uint32_t length = le32(p + i);
      i += 4;
      if (length > n - i) corrupt(at, "a header field runs past its header");
      const auto* b = reinterpret_cast<const char*>(p + i);
      const auto* eq = static_cast<const char*>(std::memchr(b, '=', length));
      if (eq == nullptr) corrupt(at, "a header field without '='");
      fields[std::string(b, eq)] = std::string(eq + 1, b + length);
      i += length;
    }
    return fields;
  }
  std::uint8_t op_of(const Fields& fields, std::uint64_t at) const {
    const auto it = fields.find("op");
    if (it == fields.end() || it->second.size() != 1) corrupt(at, "a record without its op");
    return static_cast<std::uint8_t>(it->second[0]);
  }
  std::uint32_t u32_field(const Fields& fields, const char* name, std::uint64_t at) const {
    const auto it = fields.find(name);
    if (it == fields.end() || it->second.size() != 4)
      corrupt(at, std::string("no 4-byte field '") + name + "'");
    return le32(reinterpret_cast<const std::uint8_t*>(it->second.data()));
  }

  void connection(const Fields& header, const std::uint8_t* data, std::size_t n, std::uint64_t at) {
    const std::uint32_t id = u32_field(header, "conn", at);
    const Fields info = parse_fields(data, n, at);
    Connection c;
    const auto topic = header.find("topic");
    c.topic = topic != header.end() ? topic->second : "";
    if (info.count("type")) c.type = info.at("type");
    if (info.count("md5sum")) c.md5 = info.at("md5sum");
    connections_[id] = c;
  }

  void read_chunk(const Fields& header, const std::vector<std::uint8_t>& stored, std::uint64_t at) {
    const auto compression = header.find("compression");
    const std::uint32_t size = u32_field(header, "size", at);
    if (compression == header.end()) corrupt(at, "a chunk without its compression");
    if (size > kMaxChunkBytes) corrupt(at, "a chunk of " + std::to_string(size) + " bytes");
    std::vector<std::uint8_t> plain;
    const std::string& kind = compression->second;
    if (kind == "none") {
      if (stored.size() != size) corrupt(at, "a chunk whose size disagrees with its data");
      chunk_records(stored, at);
      return;
    }
    plain.resize(size);
    if (kind == "bz2") {
      unsigned int out = size;
      // bzlib takes non-const pointers; it does not write the input.
      const int rc = BZ2_bzBuffToBuffDecompress(
          reinterpret_cast<char*>(plain.data()), &out,
          const_cast<char*>(reinterpret_cast<const char*>(stored.data())),
          static_cast<unsigned int>(stored.size()), 0, 0);
      if (rc != BZ_OK || out != size) corrupt(at, "a bz2 chunk that does not decompress");
    } else if (kind == "lz4") {
      LZ4F_dctx* raw = nullptr;
      if (LZ4F_isError(LZ4F_createDecompressionContext(&raw, LZ4F_VERSION)))
        corrupt(at, "lz4 context");
      std::unique_ptr<LZ4F_dctx, decltype(&LZ4F_freeDecompressionContext)> dctx(
          raw, &LZ4F_freeDecompressionContext);
      std::size_t in_used = 0, out_used = 0;
      std::size_t hint = 1;
      while (hint != 0 && in_used < stored.size() && out_used <= plain.size()) {
        std::size_t in = stored.size() - in_used, out = plain.size() - out_used;
        hint = LZ4F_decompress(dctx.get(), plain.data() + out_used, &out, stored.data() + in_used,
                               &in, nullptr);
        if (LZ4F_isError(hint)) corrupt(at, "an lz4 chunk that does not decompress");
        if (in == 0 && out == 0) break;
        in_used += in;
        out_used += out;
      }
      if (hint != 0 || out_used != size) corrupt(at, "an lz4 chunk that does not decompress");
    } else {
      corrupt(at, "a chunk compressed as '" + printable(kind) + "'");
    }
    chunk_records(plain, at);
  }

  void chunk_records(const std::vector<std::uint8_t>& chunk, std::uint64_t at) {
    std::size_t i = 0;
    const std::size_t n = chunk.size();
    auto block = [&](std::size_t& length) {
      if (n - i < 4) corrupt(at, "a record in a chunk ends early");
      length = le32(chunk.data() + i);
      i += 4;
      if (length > n - i) corrupt(at, "a record in a chunk runs past the chunk");
      const std::size_t begin = i;
      i += length;
      return begin;
    };
    while (i < n) {
      std::size_t header_length = 0, data_length = 0;
      const std::size_t header = block(header_length);
      const std::size_t data = block(data_length);
      const Fields fields = parse_fields(chunk.data() + header, header_length, at);
      const std::uint8_t op = op_of(fields, at);
      if (op == kConnection) {
        connection(fields, chunk.data() + data, data_length, at);
      } else if (op == kMessageData) {
        message(fields, chunk.data() + data, data_length, at);
      }
    }
  }

  void message(const Fields& header, const std::uint8_t* data, std::size_t n, std::uint64_t at) {
    const std::uint32_t id = u32_field(header, "conn", at);
    const auto c = connections_.find(id);
    if (c == connections_.end()) corrupt(at, "a message before its connection record");
    if (c->second.type != kJointStateType) return;
    const std::string where = "'" + path_ + "' topic " + printable(c->second.topic) + " message " +
                              std::to_string(messages_[c->second.topic].size() + 1);
    if (c->second.md5 != kJointStateMd5) {
      throw Error(where + ": the JointState definition's MD5 is " + printable(c->second.md5) +
                  ", not the one of sensor_msgs/JointState (" + kJointStateMd5 +
                  "); the messages have another layout");
    }
    if (n > kMaxJointStateBytes) {
      throw Error(where + ": " + std::to_string(n) + " bytes, beyond the " +
                  std::to_string(kMaxJointStateBytes) + "-byte limit of one JointState");
    }
    const auto time = header.find("time");
    if (time == header.end() || time->second.size() != 8) corrupt(at, "a message without its time");
    const auto* t = reinterpret_cast<const std::uint8_t*>(time->second.data());
    JointStateMessage m = decode_ros1_joint_state(data, n, where);
    m.record_ns = static_cast<std::int64_t>(le32(t)) * 1'000'000'000 + le32(t + 4);
    values_ += 3 * m.name.size();
    check_value_count(values_, "'" + path_ + "'");
    messages_[c->second.topic].push_back(std::move(m));
  }

  TopicMessages select() {
    TopicMessages out;
    std::vector<std::pair<std::string, std::string>> topics;
    for (const auto& [id, c] : connections_) topics.emplace_back(c.topic, c.type);
    if (truncated_at_ > 0) {
      if (connections_.empty()) {
        throw Error("ROS bag '" + path_ + "' ends after " + std::to_string(size_) +
                    " bytes, before its first message; the file is truncated: copy it again");
      }
      out.warnings.push_back("'" + path_ + "' ends inside a record at byte " +
                             std::to_string(truncated_at_) +
                             " (an interrupted recording, or a partial copy): the messages before "
                             "it are read");
    }
    out.topic = choose_topic(topics, kJointStateType, requested_, path_, out.notes);
    out.messages = std::move(messages_[out.topic]);
    // A bag is read in record time order (what rosbag's View gives); chunks are written in it.
    std::stable_sort(out.messages.begin(), out.messages.end(),
                     [](const JointStateMessage& a, const JointStateMessage& b) {
                       return a.record_ns < b.record_ns;
                     });
    return out;
  }

  std::string path_, requested_;
  std::unique_ptr<std::FILE, FileCloser> file_;
  std::uint64_t size_ = 0, offset_ = 0, truncated_at_ = 0;
  std::map<std::uint32_t, Connection> connections_;
  std::map<std::string, std::vector<JointStateMessage>> messages_;
  std::size_t values_ = 0;
};

}  // namespace

TopicMessages read_rosbag1(const std::string& path, const std::string& topic) {
  return BagReader(path, topic).read();
}

}  // namespace dynid::ros_detail
