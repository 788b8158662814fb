#include "dynid/workflow/project.hpp"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <sstream>

#include "dynid/common/error.hpp"

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
// Written beside the results; its presence marks a folder a previous `dynid run` may replace.
const char* const kCommandsFile = "commands.txt";

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

// A recorded run given by the user: a path, or {join: [files], columns: [names]} for runs logged
// as several files side by side (one row per sample in each, e.g. positions and currents).
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
    const std::string key = kv.first.as<std::string>();
    if (key == "join" && kv.second.IsSequence()) {
      for (const auto& f : kv.second) files.push_back(existing(f.as<std::string>()));
    } else if (key == "columns" && kv.second.IsSequence()) {
      for (const auto& c : kv.second) columns.push_back(c.as<std::string>());
    } else {
      throw UsageError(where + ": unknown key '" + key +
                       "' in a data entry (or not a list); valid keys are join, columns");
    }
  }
  if (files.empty() || columns.empty()) {
    throw UsageError(where + ": a joined data entry needs join: [files] and columns: [names]");
  }
  // The files' own header rows are replaced by `columns`; the rows are pasted side by side.
  std::vector<std::ifstream> in;
  size_t fields = 0;
  for (const auto& f : files) {
    in.emplace_back(f);
    std::string header;
    if (!std::getline(in.back(), header)) throw Error(where + ": data file '" + f + "' is empty");
    fields += std::count(header.begin(), header.end(), ',') + 1;
  }
  if (fields != columns.size()) {
    throw UsageError(where + ": the joined files have " + std::to_string(fields) +
                     " columns but columns names " + std::to_string(columns.size()) +
                     "; give one name per column");
  }
  const std::string name = "run" + std::to_string(index + 1) + ".csv";
  std::ofstream out(name);
  out << join(columns, ",") << '\n';
  for (long row = 2;; ++row) {
    std::string line, merged;
    int ended = 0;
    for (size_t i = 0; i < in.size(); ++i) {
      if (!std::getline(in[i], line)) {
        ++ended;
        continue;
      }
      if (!line.empty() && line.back() == '\r') line.pop_back();
      merged += (i ? "," : "") + line;
    }
    if (ended == static_cast<int>(in.size())) break;
    if (ended) {
      throw Error(where + ": the joined files end at different rows (one ends at row " +
                  std::to_string(row - 1) + " of " + join(files) + "); give files of one run");
    }
    out << merged << '\n';
  }
  if (!out) throw Error(where + ": could not write " + name + " in the output folder");
  return name;
}

// The stage's keys as command-line words, checked against the command's registered flags.
std::vector<std::string> stage_flags(const YAML::Node& node, const StageWiring& stage,
                                     const std::vector<CommandFlag>& flags,
                                     const fs::path& project_dir, const std::string& where) {
  std::vector<std::string> valid;
  for (const auto& f : flags) {
    const bool written = std::any_of(stage.outputs.begin(), stage.outputs.end(),
                                     [&](const auto& o) { return o.flag == f.name; });
    if (!written && f.name != "help") valid.push_back(f.name);
  }
  if (!node.IsNull() && !node.IsMap()) {
    throw UsageError(where + ": give a mapping of " + stage.command + " flags (e.g. " +
                     (valid.empty() ? std::string("key") : valid.front()) + ": value) or nothing");
  }
  std::vector<std::string> args;
  if (node.IsNull()) return args;
  for (const auto& kv : node) {
    const std::string key = kv.first.as<std::string>();
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
    if (!flag->takes_value) {
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
  YAML::Node root;
  try {
    root = YAML::LoadFile(project.string());
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
    const std::string key = kv.first.as<std::string>();
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
  fs::path output =
      options.output.empty() ? fs::path(text(kOutputKey)) : fs::absolute(options.output);
  if (output.empty()) {
    throw UsageError(where + ": 'output' is missing; give the folder the study is written to");
  }
  if (output.is_relative()) output = project_dir / output;
  output = output.lexically_normal();
  if (output.filename().empty()) output = output.parent_path();

  // Check every stage's keys before anything runs.
  std::vector<std::pair<const StageWiring*, std::vector<std::string>>> plan;
  for (const auto& stage : project_stages()) {
    if (!root[stage.command]) continue;
    plan.emplace_back(&stage, stage_flags(root[stage.command], stage, flags[stage.command],
                                          project_dir, where + ": " + stage.command));
  }
  if (plan.empty() && !root[kDataKey]) {
    throw UsageError(where + ": no stage to run; add some of " +
                     join(std::vector<std::string>(valid.begin() + 3, valid.end())));
  }

  // A folder is replaced only when a previous `dynid run` wrote it.
  if (fs::exists(output, ec) && !fs::is_empty(output, ec) &&
      !fs::exists(output / kCommandsFile, ec)) {
    throw Error(where + ": output folder " + output.string() +
                " exists and was not written by dynid run; choose another output or remove it");
  }
  fs::path partial = output;
  partial += ".partial";
  fs::remove_all(partial);
  fs::create_directories(partial);

  ProjectResult result;
  result.output_dir = output.string();
  try {
    std::map<std::string, std::vector<std::string>> artefacts;
    artefacts["robot"] = {resolve(robot, project_dir)};
    if (const YAML::Node data = root[kDataKey]) {
      std::vector<YAML::Node> items;
      if (data.IsSequence()) {
        for (const auto& item : data) items.push_back(item);
      } else {
        items.push_back(data);
      }
      in_folder(partial, "data.txt", [&] {
        for (size_t i = 0; i < items.size(); ++i) {
          artefacts["run"].push_back(
              data_file(items[i], where + ": data", project_dir, static_cast<int>(i)));
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
    fs::copy_file(project, partial / project.filename(), fs::copy_options::overwrite_existing);
    std::ofstream commands(partial / kCommandsFile);
    commands << "# written by dynid run " << project.filename().string()
             << "; each line ran in this folder\n";
    for (const auto& c : result.commands) {
      std::string line = "dynid";
      for (const auto& w : c) line += " " + quoted(w);
      commands << line << '\n';
    }
    if (!commands) throw Error(where + ": could not write " + (partial / kCommandsFile).string());
  } catch (...) {
    fs::remove_all(partial, ec);
    throw;
  }
  fs::remove_all(output);
  fs::rename(partial, output);
  return result;
}

}  // namespace dynid
