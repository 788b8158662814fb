#include "dynid/workflow/project.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cerrno>
#include <csignal>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <set>
#include <sstream>

#include "dynid/common/error.hpp"
#include "dynid/common/input_file.hpp"
#include "dynid/io/atomic_file.hpp"
#include "dynid/io/csv_reader.hpp"
#include "dynid/sim/pid_gains.hpp"

namespace dynid {

namespace fs = std::filesystem;

const std::vector<StageWiring>& project_stages() {
  // One line per stage, in the order they run. A stage whose command is not registered on this
  // build is simply not a valid key.
  static const std::vector<StageWiring> kStages = {
      {"model", {{"robot", "robot"}}, {{"json", "model.json", "model"}}},
      {"excite",
       {{"robot", "robot"}},
       {{"out", "trajectory.csv", "trajectory"}, {"json", "excitation.json", "excitation"}}},
      {"simulate", {{"robot", "robot"}, {"trajectory", "trajectory"}}, {{"out", "run.csv", "run"}}},
      {"identify", {{"robot", "robot"}, {"data", "run"}}, {{"out", "result.json", "result"}}},
      {"validate",
       {{"robot", "robot"}, {"params", "result"}, {"data", "run"}},
       {{"json", "validation.json", "validation"}, {"predicted", "predicted.csv", "prediction"}}},
      {"export", {{"robot", "robot"}, {"params", "result"}}, {{"out", "identified.urdf", "urdf"}}},
      {"report",
       {{"in", "result"}, {"in", "validation"}, {"in", "excitation"}},
       {{"out", "report.html", "report"}}},
  };
  return kStages;
}

namespace {

// Top-level keys that are not stages.
const char* const kOutputKey = "output";
const char* const kRobotKey = "robot";
const char* const kDataKey = "data";
// Written beside the results: the command lines of the stages.
const char* const kCommandsFile = "commands.txt";
// The marker of a folder dynid run wrote: its first line is kMarkerHeader, then the state
// ("state: writing <pid>" while the stages run in <output>.partial, "state: complete" after), the
// project file and one "file: NAME" line per entry of the folder. A folder is replaced only when
// it holds this marker and nothing the marker does not list.
const char* const kMarkerFile = ".dynid-run";
const char* const kMarkerHeader =
    "# dynid run output folder: dynid run replaces it while this file lists everything in it";
// Above this, a project file or a marker is not what it claims to be.
constexpr std::size_t kMaxProjectFileBytes = std::size_t{16} << 20;

std::string join(const std::vector<std::string>& words, const char* sep = ", ") {
  std::string s;
  for (const auto& w : words) s += (s.empty() ? "" : sep) + w;
  return s;
}

std::string quoted(const std::string& word) {
  if (!word.empty() && word.find_first_not_of("abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ"
                                              "0123456789-_./:=,+") == std::string::npos) {
    return word;
  }
  std::string s = "'";
  for (char c : word) s += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return s + "'";
}

// A value's text; a relative path naming a file beside the project file becomes absolute, since
// stages run in the output folder.
std::string resolve(const std::string& value, const fs::path& project_dir) {
  if (value.empty() || fs::path(value).is_absolute()) return value;
  std::error_code ec;
  const fs::path beside = project_dir / value;
  // Files only: a folder named like a built-in robot must not turn `robot: planar2` into a path.
  return fs::is_regular_file(beside, ec) ? beside.lexically_normal().string() : value;
}

// ---- Reading with a cap -------------------------------------------------------------------------

// ---- The marker of a folder dynid run wrote -----------------------------------------------------

struct Marker {
  bool valid = false;
  bool complete = false;  // else "writing"
  long pid = 0;           // of the run writing it
  std::set<std::string> files;
};

Marker read_marker(const fs::path& folder) {
  Marker m;
  std::string text;
  try {
    // Not followed: a link planted in place of the marker does not vouch for the folder.
    text = read_regular_file((folder / kMarkerFile).string(), std::size_t{1} << 20, "marker", true);
  } catch (const Error&) {
    return m;
  }
  std::istringstream in(text);
  std::string line;
  if (!std::getline(in, line) || line != kMarkerHeader) return m;
  if (!std::getline(in, line)) return m;
  if (line == "state: complete") {
    m.complete = true;
  } else if (line.rfind("state: writing ", 0) == 0) {
    char* end = nullptr;
    const char* digits = line.c_str() + std::strlen("state: writing ");
    m.pid = std::strtol(digits, &end, 10);
    if (end == digits || *end != '\0' || m.pid <= 0) return m;
  } else {
    return m;
  }
  while (std::getline(in, line)) {
    if (line.rfind("file: ", 0) == 0) m.files.insert(line.substr(6));
  }
  m.valid = true;
  return m;
}

void write_marker(const fs::path& folder, const fs::path& project, bool complete) {
  std::string text = std::string(kMarkerHeader) + "\n";
  text += complete ? std::string("state: complete\n")
                   : "state: writing " + std::to_string(static_cast<long>(::getpid())) + "\n";
  std::string shown = project.string();
  std::replace(shown.begin(), shown.end(), '\n', '?');
  text += "project: " + shown + "\n";
  if (complete) {
    std::set<std::string> names = {kMarkerFile};
    for (const auto& e : fs::directory_iterator(folder)) names.insert(e.path().filename().string());
    for (const auto& n : names) {
      if (n.find('\n') == std::string::npos) text += "file: " + n + "\n";
    }
  }
  write_text_atomic((folder / kMarkerFile).string(), text);
}

// Entries of `folder` the marker does not list, sorted.
std::vector<std::string> unlisted(const fs::path& folder, const Marker& m) {
  std::vector<std::string> names;
  std::error_code ec;
  for (fs::directory_iterator it(folder, ec), end; !ec && it != end; it.increment(ec)) {
    const std::string name = it->path().filename().string();
    if (name != kMarkerFile && !m.files.count(name)) names.push_back(name);
  }
  std::sort(names.begin(), names.end());
  return names;
}

// Throws unless `output` may be replaced: absent, an empty folder, or a folder an earlier run
// wrote (its marker complete and listing every entry in it).
void check_replaceable(const fs::path& output, const std::string& where) {
  struct stat st {};
  if (::lstat(output.c_str(), &st) != 0) return;
  if (S_ISLNK(st.st_mode)) {
    throw Error(where + ": output '" + output.string() +
                "' is a symbolic link; dynid run replaces its output folder and does not follow "
                "links: give the folder's real path");
  }
  if (!S_ISDIR(st.st_mode)) {
    throw Error(where + ": output '" + output.string() +
                "' exists and is not a folder; choose another output");
  }
  std::error_code ec;
  if (fs::is_empty(output, ec) && !ec) return;
  const Marker m = read_marker(output);
  if (!m.valid || !m.complete) {
    throw Error(where + ": output folder " + output.string() +
                " exists and was not written by dynid run (no valid " + kMarkerFile +
                " in it); choose another output or remove it");
  }
  const std::vector<std::string> extra = unlisted(output, m);
  if (!extra.empty()) {
    const std::vector<std::string> shown(extra.begin(),
                                         extra.begin() + std::min<std::size_t>(extra.size(), 3));
    throw Error(where + ": output folder " + output.string() + " holds " + join(shown) +
                (extra.size() > 3 ? " and " + std::to_string(extra.size() - 3) + " more" : "") +
                ", which dynid run did not write; move " + (extra.size() > 1 ? "them" : "it") +
                " out of the folder or choose another output");
  }
}

bool process_alive(long pid) {
  if (pid <= 0 || pid == static_cast<long>(::getpid())) return false;
  return ::kill(static_cast<pid_t>(pid), 0) == 0 || errno == EPERM;
}

// Creates <output>.partial for this run, after removing one an earlier run left (its marker
// valid, its writer gone). A folder of that name dynid run did not create is refused.
void prepare_partial(const fs::path& partial, const fs::path& project, const std::string& where) {
  std::error_code ec;
  fs::create_directories(partial.parent_path(), ec);
  struct stat st {};
  if (::lstat(partial.c_str(), &st) == 0) {
    const std::string refused = where + ": " + partial.string() +
                                " exists and was not created by dynid run; move it away or "
                                "choose another output";
    if (!S_ISDIR(st.st_mode)) throw Error(refused);
    if (!fs::is_empty(partial, ec) || ec) {
      const Marker m = read_marker(partial);
      if (!m.valid) throw Error(refused);
      if (!m.complete && process_alive(m.pid)) {
        throw Error(where + ": " + partial.string() +
                    " is being written by another dynid run (pid " + std::to_string(m.pid) +
                    "); wait for it to finish or choose another output");
      }
    }
    fs::remove_all(partial, ec);
    if (ec) {
      throw Error(where + ": cannot remove the leftover " + partial.string() + " (" + ec.message() +
                  "); remove it by hand");
    }
  }
  if (::mkdir(partial.c_str(), 0777) != 0) {
    throw Error(where + ": cannot create " + partial.string() + " (" + std::strerror(errno) +
                "); check that the folder of the output exists and is writable");
  }
  write_marker(partial, project, false);
}

// True when `inner` is `outer` or lies inside it (both canonical).
bool within(const fs::path& inner, const fs::path& outer) {
  auto i = inner.begin();
  for (auto o = outer.begin(); o != outer.end(); ++o, ++i) {
    if (o->empty()) continue;  // a trailing separator
    if (i == inner.end() || *i != *o) return false;
  }
  return true;
}

fs::path canonical_or_normal(const fs::path& p) {
  std::error_code ec;
  fs::path c = fs::weakly_canonical(p, ec);
  return ec ? p.lexically_normal() : c;
}

// ---- Recorded runs ------------------------------------------------------------------------------

// A recorded run given by the user: a path, or {join: [files], columns: [names]} for runs logged
// as several files side by side (one row per sample in each, e.g. positions and currents).
// Joined files are read from under the project folder only, regular files, at most
// kMaxCsvFileBytes together (the joined run is read back with that cap), and the result is
// written as run<index+1>.csv in the working directory (the output folder being built).
std::string data_file(const YAML::Node& item, const std::string& where, const fs::path& project_dir,
                      int index) {
  const auto existing = [&](const std::string& name) {
    const fs::path p = fs::path(name).is_absolute() ? fs::path(name) : project_dir / name;
    std::error_code ec;
    if (!fs::is_regular_file(p, ec)) {
      throw Error(where + ": data file '" + name + "' not found (looked for " + p.string() +
                  "); give the path relative to the project file or an absolute one");
    }
    return p.lexically_normal().string();
  };
  if (item.IsScalar()) return existing(item.Scalar());
  if (!item.IsMap()) {
    throw UsageError(where + ": each data entry is a file path or {join: [files], columns: [...]}");
  }
  std::vector<std::string> files, columns;
  for (const auto& kv : item) {
    const std::string key = kv.first.Scalar();
    if (key == "join" && kv.second.IsSequence()) {
      for (const auto& f : kv.second) {
        if (!f.IsScalar() || f.Scalar().empty()) {
          throw UsageError(where + ": join takes a list of file names");
        }
        files.push_back(f.Scalar());
      }
    } else if (key == "columns" && kv.second.IsSequence()) {
      for (const auto& c : kv.second) {
        if (!c.IsScalar()) throw UsageError(where + ": columns takes a list of names");
        columns.push_back(c.Scalar());
      }
    } else {
      throw UsageError(where + ": unknown key '" + key +
                       "' in a data entry (or not a list); valid keys are join, columns");
    }
  }
  if (files.empty() || columns.empty()) {
    throw UsageError(where + ": a joined data entry needs join: [files] and columns: [names]");
  }
  // Under the project folder as written: no absolute path, no way up with "..".
  for (const auto& f : files) {
    const fs::path normal = fs::path(f).lexically_normal();
    if (fs::path(f).is_absolute() || (!normal.empty() && *normal.begin() == "..")) {
      throw UsageError(where + ": joined file '" + f +
                       "' is outside the project folder; joined files are read from under the "
                       "folder of the project file only: put the file (or a link to it) there");
    }
  }
  // The files' own header rows are replaced by `columns`; the rows are pasted side by side.
  std::vector<std::string> texts;
  std::size_t total = 0, fields = 0;
  for (const auto& f : files) {
    const fs::path p = (project_dir / f).lexically_normal();
    std::error_code ec;
    if (!fs::exists(p, ec)) {
      throw Error(where + ": data file '" + f + "' not found (looked for " + p.string() +
                  "); give the path relative to the project file");
    }
    texts.push_back(read_regular_file(p.string(), kMaxCsvFileBytes, where + ": joined file"));
    total += texts.back().size();
    if (total > kMaxCsvFileBytes) {
      throw Error(where + ": the joined files are larger than " +
                  std::to_string(kMaxCsvFileBytes >> 20) +
                  " MiB together, the limit for a run read into memory; join shorter files");
    }
    const std::string& t = texts.back();
    const std::string header = t.substr(0, t.find('\n'));
    if (t.empty()) throw Error(where + ": data file '" + f + "' is empty");
    fields += std::count(header.begin(), header.end(), ',') + 1;
  }
  if (fields != columns.size()) {
    throw UsageError(where + ": the joined files have " + std::to_string(fields) +
                     " columns but columns names " + std::to_string(columns.size()) +
                     "; give one name per column");
  }
  const std::string name = "run" + std::to_string(index + 1) + ".csv";
  write_file_atomic(name, [&](std::ostream& out) {
    out << join(columns, ",") << '\n';
    std::vector<std::size_t> at(texts.size(), 0);
    for (auto& a : at) a = std::string::npos;  // before the header
    const auto next_line = [&](std::size_t i, std::string& line) {
      const std::string& t = texts[i];
      std::size_t start = at[i] == std::string::npos ? 0 : at[i];
      if (start >= t.size()) return false;
      std::size_t end = t.find('\n', start);
      if (end == std::string::npos) end = t.size();
      line.assign(t, start, end - start);
      at[i] = end + 1;
      if (!line.empty() && line.back() == '\r') line.pop_back();
      return true;
    };
    std::string line, merged;
    for (std::size_t i = 0; i < texts.size(); ++i) next_line(i, line);  // the header rows
    for (long row = 2;; ++row) {
      merged.clear();
      std::size_t ended = 0;
      for (std::size_t i = 0; i < texts.size(); ++i) {
        if (!next_line(i, line)) {
          ++ended;
          continue;
        }
        merged += (i ? "," : "") + line;
      }
      if (ended == texts.size()) break;
      if (ended) {
        throw Error(where + ": the joined files end at different rows (one ends at row " +
                    std::to_string(row - 1) + " of " + join(files) + "); give files of one run");
      }
      if (merged.size() > kMaxCsvLineBytes) {
        throw Error(where + ": row " + std::to_string(row) +
                    " of the joined files is longer than " +
                    std::to_string(kMaxCsvLineBytes >> 20) + " MiB; check that they are CSV files");
      }
      out << merged << '\n';
    }
  });
  return name;
}

// ---- Stages -------------------------------------------------------------------------------------

// A file a stage key names for its command to write (`history: rls.csv`): a plain file name, so
// that it lands in the output folder and nowhere else.
void check_output_name(const std::string& name, const std::string& key, const std::string& where) {
  const fs::path p(name);
  const bool control = std::any_of(name.begin(), name.end(), [](char c) {
    return static_cast<unsigned char>(c) < 0x20 || c == 0x7F;
  });
  if (name.empty() || p.is_absolute() || name.find('/') != std::string::npos || name == "." ||
      name == ".." || control) {
    throw UsageError(where + ": '" + key + ": " + name +
                     "' must be a file name in the output folder (no folder, no .., not absolute); "
                     "give e.g. " +
                     key + ": " + key + (key == "report" ? ".html" : ".csv"));
  }
}

// The stage's keys as command-line words, checked against the command's registered flags. The
// file names of output keys are appended to `written` as {key, name}.
std::vector<std::string> stage_flags(const YAML::Node& node, const StageWiring& stage,
                                     const std::vector<CommandFlag>& flags,
                                     const fs::path& project_dir, const std::string& where,
                                     std::vector<std::pair<std::string, std::string>>& written) {
  std::vector<std::string> valid;
  for (const auto& f : flags) {
    const bool set_by_runner = std::any_of(stage.outputs.begin(), stage.outputs.end(),
                                           [&](const auto& o) { return o.flag == f.name; });
    if (!set_by_runner && f.name != "help") valid.push_back(f.name);
  }
  if (!node.IsNull() && !node.IsMap()) {
    throw UsageError(where + ": give a mapping of " + stage.command + " flags (e.g. " +
                     (valid.empty() ? std::string("key") : valid.front()) + ": value) or nothing");
  }
  std::vector<std::string> args;
  if (node.IsNull()) return args;
  for (const auto& kv : node) {
    const std::string key = kv.first.Scalar();
    const auto output = std::find_if(stage.outputs.begin(), stage.outputs.end(),
                                     [&](const auto& o) { return o.flag == key; });
    if (output != stage.outputs.end()) {
      throw UsageError(where + ": '" + key + "' is set by the project runner (" + output->file +
                       " in the output folder); remove it");
    }
    const auto flag = std::find_if(flags.begin(), flags.end(),
                                   [&](const CommandFlag& f) { return f.name == key; });
    if (flag == flags.end() || key == "help") {
      throw UsageError(where + ": unknown key '" + key + "'; valid keys are " + join(valid) +
                       " (the flags of dynid " + stage.command + " without --)");
    }
    const YAML::Node& v = kv.second;
    if (flag->writes) {
      // Never resolved beside the project file: an output goes into the output folder.
      if (!v.IsScalar()) throw UsageError(where + ": '" + key + "' takes one file name");
      check_output_name(v.Scalar(), key, where);
      written.emplace_back(key, v.Scalar());
      args.insert(args.end(), {"--" + key, v.Scalar()});
    } else if (!flag->takes_value) {
      bool on = false;
      if (!v.IsScalar() || !YAML::convert<bool>::decode(v, on)) {
        throw UsageError(where + ": '" + key + "' is a switch; give true or false");
      }
      if (on) args.push_back("--" + key);
    } else if (v.IsScalar()) {
      args.insert(args.end(), {"--" + key, resolve(v.Scalar(), project_dir)});
    } else if (v.IsSequence() && v.size() > 0) {
      std::vector<std::string> items;
      for (const auto& item : v) {
        if (!item.IsScalar()) throw UsageError(where + ": '" + key + "' takes a list of values");
        items.push_back(resolve(item.Scalar(), project_dir));
      }
      if (flag->repeatable) {
        for (const auto& item : items) args.insert(args.end(), {"--" + key, item});
      } else {
        args.insert(args.end(), {"--" + key, join(items, ",")});
      }
    } else {
      throw UsageError(where + ": '" + key + "' needs a value or a list of values");
    }
  }
  return args;
}

// Runs `body` with `dir` as the working directory and std::cout going to `log`.
template <class Body>
void in_folder(const fs::path& dir, const fs::path& log, Body&& body) {
  struct Restore {
    fs::path cwd;
    std::streambuf* out;
    ~Restore() {
      std::cout.rdbuf(out);
      std::error_code ec;
      fs::current_path(cwd, ec);
    }
  };
  std::ofstream file(dir / log);
  Restore restore{fs::current_path(), std::cout.rdbuf(file.rdbuf())};
  fs::current_path(dir);
  body();
}

}  // namespace

ProjectResult run_project(const ProjectOptions& options, const CommandTable& table,
                          const ProgressCallback& progress) {
  const fs::path project = fs::absolute(options.project_file);
  const std::string where = project.filename().string();
  std::error_code ec;
  if (!fs::is_regular_file(project, ec)) {
    throw Error("project file '" + options.project_file + "' not found; give a YAML project file");
  }
  const fs::path project_dir = project.parent_path();
  const std::string project_text =
      read_regular_file(project.string(), kMaxProjectFileBytes, "project file");
  YAML::Node root;
  try {
    root = YAML::Load(project_text);
  } catch (const YAML::Exception& e) {
    throw Error(where + ": not valid YAML (" + e.what() + "); fix the file");
  }
  if (!root.IsMap()) {
    throw UsageError(where + ": the project is a mapping with output, robot and stage keys");
  }

  std::vector<std::string> valid = {kOutputKey, kRobotKey, kDataKey};
  std::map<std::string, std::vector<CommandFlag>> flags;
  for (const auto& stage : project_stages()) {
    std::vector<CommandFlag> f;
    if (table.flags(stage.command, f)) {
      flags[stage.command] = f;
      valid.push_back(stage.command);
    }
  }
  for (const auto& kv : root) {
    const std::string key = kv.first.Scalar();
    if (std::find(valid.begin(), valid.end(), key) == valid.end()) {
      throw UsageError(where + ": unknown key '" + key + "'; valid keys are " + join(valid));
    }
  }
  const auto text = [&](const char* key) {
    const YAML::Node n = root[key];
    if (n && !n.IsScalar()) throw UsageError(where + ": '" + key + "' takes one value");
    return n ? n.Scalar() : std::string();
  };
  if (root["simulate"] && root[kDataKey]) {
    throw UsageError(where +
                     ": give either simulate (a simulated experiment) or data (recorded "
                     "runs), not both");
  }
  const std::string robot = text(kRobotKey);
  if (robot.empty())
    throw UsageError(where + ": 'robot' is missing; give a built-in name or a model");
  const std::string output_text = options.output.empty() ? text(kOutputKey) : options.output;
  fs::path output =
      options.output.empty() ? fs::path(text(kOutputKey)) : fs::absolute(options.output);
  if (output.empty()) {
    throw UsageError(where + ": 'output' is missing; give the folder the study is written to");
  }
  if (output.is_relative()) output = project_dir / output;
  output = output.lexically_normal();
  if (output.filename().empty()) output = output.parent_path();
  // The output folder is replaced as a whole: never the project's own folder or one holding it.
  const fs::path canonical_output = canonical_or_normal(output),
                 canonical_project_dir = canonical_or_normal(project_dir);
  if (within(canonical_project_dir, canonical_output)) {
    throw UsageError(where + ": output '" + output_text + "' is " +
                     (canonical_output == canonical_project_dir ? "the folder of the project file"
                                                                : "a folder holding the project") +
                     "; dynid run replaces its output folder as a whole, so give a new folder, "
                     "e.g. output: study");
  }

  // Check every stage's keys before anything runs.
  std::vector<std::pair<const StageWiring*, std::vector<std::string>>> plan;
  std::vector<std::pair<std::string, std::string>> written;  // {stage: key, file name}
  for (const auto& stage : project_stages()) {
    if (!root[stage.command]) continue;
    std::vector<std::pair<std::string, std::string>> keys;
    plan.emplace_back(&stage, stage_flags(root[stage.command], stage, flags[stage.command],
                                          project_dir, where + ": " + stage.command, keys));
    for (auto& k : keys) written.emplace_back(stage.command + ": " + k.first, k.second);
  }
  if (plan.empty() && !root[kDataKey]) {
    throw UsageError(where + ": no stage to run; add some of " +
                     join(std::vector<std::string>(valid.begin() + 3, valid.end())));
  }

  // The names the runner writes into the folder; a stage's own output keys must not take them.
  std::map<std::string, std::string> taken = {
      {kMarkerFile, "dynid run's marker"},
      {kCommandsFile, "the command lines"},
      {project.filename().string(), "the copy of the project file"},
      {"data.txt", "what reading the data printed"},
  };
  std::vector<YAML::Node> data_items;
  if (const YAML::Node data = root[kDataKey]) {
    if (data.IsSequence()) {
      for (const auto& item : data) data_items.push_back(item);
    } else {
      data_items.push_back(data);
    }
  }
  for (size_t i = 0; i < data_items.size(); ++i) {
    if (data_items[i].IsMap()) taken["run" + std::to_string(i + 1) + ".csv"] = "a joined data run";
  }
  for (const auto& [stage, args] : plan) {
    if (stage->command + ".txt" == project.filename()) {
      throw UsageError(where + ": the project file is named like the log of the " + stage->command +
                       " stage; rename the project file (e.g. study.yaml)");
    }
    taken.emplace(stage->command + ".txt", "what " + stage->command + " printed");
    for (const auto& out : stage->outputs) {
      if (out.file == project.filename()) {
        throw UsageError(where + ": the project file is named like " + out.file + ", which the " +
                         stage->command +
                         " stage writes; rename the project file (e.g. study.yaml)");
      }
      taken.emplace(out.file, stage->command + "'s " + out.flag);
      if (stage->command == "simulate" && out.flag == "out") {
        taken.emplace(gains_file_for_run(out.file), "simulate's gains");
      }
    }
  }
  for (const auto& [key, name] : written) {
    const auto clash = taken.find(name);
    if (clash != taken.end()) {
      throw UsageError(where + ": " + key + ": '" + name + "' is already " + clash->second +
                       " in the output folder; give another file name");
    }
    taken.emplace(name, key);
  }

  // A folder is replaced only when a previous `dynid run` wrote it.
  check_replaceable(output, where);
  fs::path partial = output;
  partial += ".partial";
  prepare_partial(partial, project, where);

  ProjectResult result;
  result.output_dir = output.string();
  try {
    std::map<std::string, std::vector<std::string>> artefacts;
    artefacts["robot"] = {resolve(robot, project_dir)};
    if (!data_items.empty()) {
      in_folder(partial, "data.txt", [&] {
        for (size_t i = 0; i < data_items.size(); ++i) {
          artefacts["run"].push_back(
              data_file(data_items[i], where + ": data", project_dir, static_cast<int>(i)));
        }
      });
    }
    for (size_t s = 0; s < plan.size(); ++s) {
      const StageWiring& stage = *plan[s].first;
      const std::vector<CommandFlag>& f = flags[stage.command];
      std::vector<std::string> args = {stage.command};
      std::map<std::string, bool> given;
      for (size_t i = 0; i < plan[s].second.size(); ++i) {
        if (plan[s].second[i].rfind("--", 0) == 0) given[plan[s].second[i].substr(2)] = true;
      }
      for (const auto& in : stage.inputs) {
        if (given[in.flag] || !artefacts.count(in.artefact)) continue;
        const auto flag = std::find_if(f.begin(), f.end(),
                                       [&](const CommandFlag& c) { return c.name == in.flag; });
        if (flag == f.end()) continue;
        for (const auto& file : artefacts[in.artefact]) {
          args.insert(args.end(), {"--" + in.flag, file});
          if (!flag->repeatable) {
            given[in.flag] = true;
            break;
          }
        }
      }
      for (const auto& out : stage.outputs) args.insert(args.end(), {"--" + out.flag, out.file});
      args.insert(args.end(), plan[s].second.begin(), plan[s].second.end());
      if (progress) {
        progress(static_cast<double>(s) / static_cast<double>(plan.size()),
                 "stage " + std::to_string(s + 1) + "/" + std::to_string(plan.size()) + ": dynid " +
                     join(args, " "));
      }
      try {
        in_folder(partial, stage.command + ".txt", [&] { table.run(args); });
      } catch (const UsageError& e) {
        throw UsageError(where + ": " + stage.command + ": " + e.what());
      } catch (const Error& e) {
        throw Error(where + ": " + stage.command + ": " + e.what());
      }
      for (const auto& out : stage.outputs) {
        if (fs::exists(partial / out.file, ec)) artefacts[out.artefact] = {out.file};
      }
      result.commands.push_back(args);
    }
    write_text_atomic((partial / project.filename()).string(), project_text);
    std::string commands = "# written by dynid run " + project.filename().string() +
                           "; each line ran in this folder\n";
    for (const auto& c : result.commands) {
      std::string line = "dynid";
      for (const auto& w : c) line += " " + quoted(w);
      commands += line + '\n';
    }
    write_text_atomic((partial / kCommandsFile).string(), commands);
    write_marker(partial, project, true);
    // Again now: files may have been put into the old folder while the stages ran.
    check_replaceable(output, where);
  } catch (...) {
    fs::remove_all(partial, ec);
    throw;
  }
  // From here the complete study is kept in <output>.partial whatever fails.
  if (fs::exists(output, ec)) {
    fs::remove_all(output, ec);
    if (ec) {
      throw Error(where + ": cannot remove the earlier " + output.string() + " (" + ec.message() +
                  "); the new study is in " + partial.string() + ": remove the old one by hand");
    }
  }
  fs::rename(partial, output, ec);
  if (ec) {
    throw Error(where + ": cannot rename " + partial.string() + " to " + output.string() + " (" +
                ec.message() + "); the study is complete in " + partial.string());
  }
  return result;
}

}  // namespace dynid
