#include "dynid/identification/streaming_partial.hpp"

#include <cmath>
#include <cstring>
#include <limits>
#include <ostream>

#include "dynid/common/error.hpp"
#include "dynid/common/input_file.hpp"
#include "dynid/io/atomic_file.hpp"

namespace dynid {

namespace {

// Written in the writer's byte order; a reader that sees it swapped was built for the other one.
constexpr std::uint32_t kByteOrderMark = 0x01020304u;
// A part holds a few summaries of (p+1)² numbers per run; a larger file is not one dynid wrote.
constexpr std::size_t kMaxPartialBytes = std::size_t{1} << 32;
// Largest JSON header and largest per-group column count accepted (sizes read from the file are
// bounded before anything is allocated from them).
constexpr std::uint64_t kMaxHeaderBytes = std::uint64_t{64} << 20;
constexpr std::int64_t kMaxColumns = 100000;

// FNV-1a over the bytes before the trailer: a flipped byte or a splice is refused, not solved.
std::uint64_t fnv1a(const char* data, std::size_t size) {
  std::uint64_t h = 14695981039346656037ull;
  for (std::size_t i = 0; i < size; ++i) {
    h ^= static_cast<unsigned char>(data[i]);
    h *= 1099511628211ull;
  }
  return h;
}

class Writer {
 public:
  template <typename T>
  void put(const T& v) {
    bytes_.append(reinterpret_cast<const char*>(&v), sizeof v);
  }
  void put_doubles(const double* v, std::size_t count) {
    bytes_.append(reinterpret_cast<const char*>(v), count * sizeof(double));
  }
  void put_text(const std::string& s) {
    put<std::uint64_t>(s.size());
    bytes_ += s;
  }
  std::string& bytes() { return bytes_; }

 private:
  std::string bytes_;
};

class Reader {
 public:
  Reader(const std::string& bytes, const std::string& path) : bytes_(bytes), path_(path) {}
  template <typename T>
  T get(const char* what) {
    need(sizeof(T), what);
    T v;
    std::memcpy(&v, bytes_.data() + at_, sizeof v);
    at_ += sizeof v;
    return v;
  }
  void get_doubles(double* out, std::size_t count, const char* what) {
    if (count > (bytes_.size() - at_) / sizeof(double)) truncated(what);
    std::memcpy(out, bytes_.data() + at_, count * sizeof(double));
    at_ += count * sizeof(double);
  }
  std::string get_text(std::uint64_t cap, const char* what) {
    const auto size = get<std::uint64_t>(what);
    if (size > cap) corrupt(std::string(what) + " length " + std::to_string(size) + " too large");
    need(static_cast<std::size_t>(size), what);
    std::string out = bytes_.substr(at_, static_cast<std::size_t>(size));
    at_ += static_cast<std::size_t>(size);
    return out;
  }
  std::size_t at() const { return at_; }
  [[noreturn]] void corrupt(const std::string& what) const {
    throw Error("partial result '" + path_ + "' is corrupt (" + what +
                "); re-make it with dynid identify --stream --partial");
  }
  [[noreturn]] void truncated(const char* what) const {
    throw Error("partial result '" + path_ + "' is truncated (it ends inside the " + what +
                "); re-make it with dynid identify --stream --partial or copy it again");
  }

 private:
  void need(std::size_t size, const char* what) const {
    if (size > bytes_.size() - at_) truncated(what);
  }
  const std::string& bytes_;
  const std::string& path_;
  std::size_t at_ = 0;
};

// The first key of `a` or `b` whose values differ (empty when equal), with both values; the
// keys of `first` are looked at first (the robot before its parameter set).
std::string first_difference(const nlohmann::json& a, const nlohmann::json& b,
                             const std::vector<std::string>& first = {}) {
  for (const std::string& key : first) {
    if (a.contains(key) && b.contains(key) && a.at(key) != b.at(key)) {
      return key + " " + a.at(key).dump() + " vs " + b.at(key).dump();
    }
  }
  for (const auto& [key, value] : a.items()) {
    if (!b.contains(key) || b.at(key) != value) {
      return key + " " + value.dump() + " vs " + (b.contains(key) ? b.at(key).dump() : "absent");
    }
  }
  for (const auto& [key, value] : b.items()) {
    if (!a.contains(key)) return key + " absent vs " + value.dump();
  }
  return {};
}

}  // namespace

void merge_stream_partials(StreamPartial& into, const StreamPartial& other,
                           const std::string& into_name, const std::string& other_name) {
  const auto refuse = [&](const std::string& what) {
    throw Error("cannot merge '" + other_name + "' into '" + into_name + "': " + what +
                "; merge only parts of one robot made with the same options");
  };
  if (std::string d =
          first_difference(into.identity, other.identity, {"robot", "joints", "layout"});
      !d.empty()) {
    refuse("they differ in " + d);
  }
  if (into.probe.rows() != other.probe.rows() || into.probe.cols() != other.probe.cols() ||
      !((into.probe - other.probe).cwiseAbs().maxCoeff() <=
        1e-9 * std::max(1.0, into.probe.cwiseAbs().maxCoeff()))) {
    refuse("their equations differ (same joint and parameter names, other kinematics or gravity)");
  }
  if (std::string d = first_difference(into.options, other.options); !d.empty()) {
    refuse("their options differ in " + d);
  }
  into.runs.insert(into.runs.end(), other.runs.begin(), other.runs.end());
}

nlohmann::json stream_partial_origin(const std::string& robot, const Model& model) {
  std::vector<std::string> joints;
  for (const Joint& j : model.joints) joints.push_back(j.name);
  nlohmann::json locks = nlohmann::json::array();
  for (const JointLock& l : model.locked_joints) {
    locks.push_back({{"name", l.name}, {"value", l.value}});
  }
  return {{"robot", robot}, {"joints", joints}, {"locks", locks}};
}

std::string stream_partial_robot(const StreamPartial& part, JointSelection& selection) {
  selection = {};
  try {
    const std::string robot = part.origin.at("robot").get<std::string>();
    const nlohmann::json& locks = part.origin.at("locks");
    if (!locks.empty()) {
      selection.joints = part.origin.at("joints").get<std::vector<std::string>>();
      for (const auto& l : locks) {
        selection.locks.push_back({l.at("name").get<std::string>(), l.at("value").get<double>()});
      }
    }
    return robot;
  } catch (const nlohmann::json::exception&) {
    throw Error(
        "the partial result does not say which robot it was made with; give the robot (--robot)");
  }
}

nlohmann::json stream_partial_result_options(const StreamPartial& part, const std::string& robot) {
  nlohmann::json used = part.options;
  used["robot"] = robot;
  used["data"] = part.runs.empty() ? std::string() : part.runs.front().file;
  if (part.runs.size() > 1) {
    std::vector<std::string> files;
    for (const StreamRun& r : part.runs) files.push_back(r.file);
    used["data_runs"] = files;
  }
  return used;
}

std::string stream_partial_bytes(const StreamPartial& part) {
  nlohmann::json runs = nlohmann::json::array();
  for (const StreamRun& r : part.runs) {
    nlohmann::json groups = nlohmann::json::array();
    for (const auto& g : r.state.groups)
      groups.push_back({{"columns", g.columns}, {"rows", g.rows}});
    runs.push_back({{"file", r.file},
                    {"samples", r.samples},
                    {"parameters", r.state.parameters},
                    {"accumulation", r.state.accumulation == Accumulation::kNormalEquations
                                         ? "normal_equations"
                                         : "householder"},
                    {"groups", groups}});
  }
  const nlohmann::json header = {{"identity", part.identity},
                                 {"options", part.options},
                                 {"origin", part.origin},
                                 {"probe", {part.probe.rows(), part.probe.cols()}},
                                 {"runs", runs}};
  Writer w;
  w.bytes().append(kStreamPartialMagic, sizeof kStreamPartialMagic);
  w.put(kStreamPartialVersion);
  w.put(kByteOrderMark);
  // Strings from the input (file names) may not be valid UTF-8: replaced, not refused.
  w.put_text(header.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace));
  w.put_doubles(part.probe.data(), static_cast<std::size_t>(part.probe.size()));
  for (const StreamRun& r : part.runs) {
    for (const auto& g : r.state.groups) {
      w.put_doubles(g.summary.data(), static_cast<std::size_t>(g.summary.size()));
    }
  }
  const std::uint64_t sum = fnv1a(w.bytes().data(), w.bytes().size());
  w.put(sum);
  return std::move(w.bytes());
}

void write_stream_partial(const std::string& path, const StreamPartial& part) {
  const std::string bytes = stream_partial_bytes(part);
  write_file_atomic(path, [&](std::ostream& out) {
    out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  });
}

StreamPartial read_stream_partial(const std::string& path) {
  return stream_partial_from_bytes(read_regular_file(path, kMaxPartialBytes, "partial result"),
                                   path);
}

StreamPartial stream_partial_from_bytes(const std::string& bytes, const std::string& path) {
  Reader r(bytes, path);
  if (bytes.size() < sizeof kStreamPartialMagic ||
      std::memcmp(bytes.data(), kStreamPartialMagic, sizeof kStreamPartialMagic) != 0) {
    throw Error("'" + path +
                "' is not a dynid partial result (no DYNIDPRT magic); give a file written by "
                "dynid identify --stream --partial");
  }
  for (std::size_t i = 0; i < sizeof kStreamPartialMagic; ++i) r.get<char>("magic");
  const auto version = r.get<std::uint32_t>("format version");
  const auto mark = r.get<std::uint32_t>("byte-order mark");
  if (mark != kByteOrderMark) {
    throw Error("partial result '" + path +
                "' was written on a machine of the other byte order; re-make it on this one");
  }
  if (version != kStreamPartialVersion) {
    throw Error("partial result '" + path + "' has format version " + std::to_string(version) +
                ", this dynid reads version " + std::to_string(kStreamPartialVersion) +
                "; re-make it with this dynid");
  }
  if (bytes.size() < sizeof(std::uint64_t) + r.at()) r.truncated("checksum");
  const std::size_t body = bytes.size() - sizeof(std::uint64_t);
  std::uint64_t sum;
  std::memcpy(&sum, bytes.data() + body, sizeof sum);
  const std::string header_text = r.get_text(kMaxHeaderBytes, "header");
  if (r.at() > body) r.truncated("header");
  if (fnv1a(bytes.data(), body) != sum) {
    // Checked after the header so that a cut-off file is called truncated where it is.
    r.corrupt("checksum mismatch: the file was cut short or changed after it was written");
  }
  StreamPartial part;
  try {
    const nlohmann::json header = nlohmann::json::parse(header_text);
    part.identity = header.at("identity");
    part.options = header.at("options");
    part.origin = header.value("origin", nlohmann::json::object());
    const auto dims = header.at("probe").get<std::vector<std::int64_t>>();
    if (dims.size() != 2 || dims[0] < 0 || dims[1] < 0 || dims[0] > kMaxColumns ||
        dims[1] > kMaxColumns) {
      r.corrupt("probe size");
    }
    // Each size is checked against the bytes left before it is allocated.
    if (static_cast<std::uint64_t>(dims[0] * dims[1]) > (body - r.at()) / sizeof(double)) {
      r.truncated("probe");
    }
    part.probe.resize(dims[0], dims[1]);
    r.get_doubles(part.probe.data(), static_cast<std::size_t>(part.probe.size()), "probe");
    for (const auto& run : header.at("runs")) {
      StreamRun out;
      out.file = run.at("file").get<std::string>();
      out.samples = run.at("samples").get<Eigen::Index>();
      out.state.parameters = run.at("parameters").get<Eigen::Index>();
      const std::string acc = run.at("accumulation").get<std::string>();
      if (acc != "normal_equations" && acc != "householder") r.corrupt("accumulation " + acc);
      out.state.accumulation =
          acc == "householder" ? Accumulation::kHouseholder : Accumulation::kNormalEquations;
      if (out.samples < 0 || out.state.parameters < 1 || out.state.parameters > kMaxColumns) {
        r.corrupt("run sizes");
      }
      for (const auto& g : run.at("groups")) {
        StreamingState::Group group;
        group.columns = g.at("columns").get<std::vector<Eigen::Index>>();
        group.rows = g.at("rows").get<Eigen::Index>();
        const auto q = static_cast<std::uint64_t>(group.columns.size()) + 1;
        if (q > static_cast<std::uint64_t>(kMaxColumns)) r.corrupt("group size");
        if (q * q > (body - r.at()) / sizeof(double)) r.truncated("summaries");
        group.summary.resize(static_cast<Eigen::Index>(q), static_cast<Eigen::Index>(q));
        r.get_doubles(group.summary.data(), static_cast<std::size_t>(q * q), "summaries");
        out.state.groups.push_back(std::move(group));
      }
      // Validates sizes, columns, finiteness and triangularity (StreamingLeastSquares).
      StreamingLeastSquares::from_state(out.state);
      part.runs.push_back(std::move(out));
    }
  } catch (const nlohmann::json::exception& e) {
    r.corrupt(std::string("header: ") + e.what());
  } catch (const Error& e) {
    const std::string text = e.what();
    if (text.rfind("partial result '", 0) == 0) throw;
    r.corrupt(text);
  }
  if (r.at() != body) r.corrupt("bytes left after the last summary");
  if (part.runs.empty()) r.corrupt("no run");
  stream_partial_options(part);  // the identity must rebuild identify's options
  return part;
}

}  // namespace dynid
