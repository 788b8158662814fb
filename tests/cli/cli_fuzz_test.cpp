// CLI-level fuzz test (issue 10, item 5): mutated input files (CSV, URDF, YAML, result JSON) and
// flag values go through every command of the built binary (compile definition DYNID_BINARY), and
// every run must keep the error contract of docs/cli.md:
// - it ends by itself (no signal, no hang: a generous per-run limit, not a speed check);
// - exit 0, or exit 1 / 2 with stderr ending in the one line that starts with "error: " (after the
//   command's echo of its choices and warnings, if any: testing::error_contract_problem);
// - stderr is valid UTF-8 without control characters (besides the line ends);
// - a failed run leaves nothing in its output folder (no partial file, no temporary);
// - a successful run writes no non-finite number: every CSV field parses as a finite number, and a
//   JSON null appears only where the model JSON documents it (root parent, unlimited limits) and
//   where identify documents it (nominal: the model file has no value).
// The mutations are drawn from a fixed seed, so every case is the same on every run. Each command
// is one test; a failing case is reported with its command line and the folder holding its inputs
// (kept under $TMPDIR/dynid_cli_fuzz/COMMAND.PID/, with replay.sh and `args`) so that it can be
// replayed by hand or recorded. The recorded reproducers of fuzz/regressions/commands/ (one folder
// each: `args`, one argument a line with the escapes \\, \n, \t and \xNN, and the files it reads)
// are replayed under the same contract.

#include <fcntl.h>
#include <signal.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <random>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "support/asan.hpp"
#include "support/cli_run.hpp"

namespace dynid {
namespace {

namespace fs = std::filesystem;

// Hang guard per run: far above what any case needs (the largest is an excitation with
// --max-time 1), so that only a run that does not end by itself reaches it.
constexpr int kRunLimitSeconds = 120;

using dynid::testing::error_contract_problem;
using dynid::testing::slurp;

void write_file(const fs::path& path, const std::string& text) {
  std::ofstream(path, std::ios::binary | std::ios::trunc) << text;
}

struct Outcome {
  int code = -1;      // exit code, -1 if killed by a signal
  int signal = 0;     // terminating signal, 0 if it exited
  bool hung = false;  // killed at kRunLimitSeconds
  std::string out, err;
};

/// Runs DYNID_BINARY with `args` in folder `dir` (stdin /dev/null, stdout/stderr captured).
Outcome run_binary(const std::vector<std::string>& args, const fs::path& dir) {
  const fs::path out_path = dir / ".stdout";
  const fs::path err_path = dir / ".stderr";
  const pid_t pid = ::fork();
  if (pid == 0) {
    if (::chdir(dir.c_str()) != 0) ::_exit(127);
    const int in = ::open("/dev/null", O_RDONLY);
    const int out = ::open(out_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    const int err = ::open(err_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    if (in < 0 || out < 0 || err < 0) ::_exit(127);
    ::dup2(in, 0);
    ::dup2(out, 1);
    ::dup2(err, 2);
#if !DYNID_UNDER_ASAN
    // A memory blow-up should end as bad_alloc in the run, not in the machine's swap;
    // AddressSanitizer reserves terabytes of address space, so not under it.
    const rlimit limit{4ul << 30, 4ul << 30};
    ::setrlimit(RLIMIT_AS, &limit);
#endif
    std::vector<char*> argv;
    std::string binary = DYNID_BINARY;
    argv.push_back(binary.data());
    std::vector<std::string> copy = args;
    for (auto& a : copy) argv.push_back(a.data());
    argv.push_back(nullptr);
    ::execv(binary.c_str(), argv.data());
    ::_exit(127);
  }
  Outcome o;
  int status = 0;
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(kRunLimitSeconds);
  while (true) {
    const pid_t done = ::waitpid(pid, &status, WNOHANG);
    if (done == pid) break;
    if (std::chrono::steady_clock::now() > deadline) {
      ::kill(pid, SIGKILL);
      ::waitpid(pid, &status, 0);
      o.hung = true;
      break;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  if (WIFEXITED(status)) o.code = WEXITSTATUS(status);
  if (WIFSIGNALED(status)) o.signal = WTERMSIG(status);
  o.out = slurp(out_path);
  o.err = slurp(err_path);
  fs::remove(out_path);
  fs::remove(err_path);
  return o;
}

/// True when `text` is well-formed UTF-8 (no overlong forms, surrogates or code points > U+10FFFF).
bool valid_utf8(const std::string& text) {
  size_t i = 0;
  while (i < text.size()) {
    const auto c = static_cast<unsigned char>(text[i]);
    int extra = 0;
    unsigned min = 0, cp = 0;
    if (c < 0x80) {
      ++i;
      continue;
    } else if ((c & 0xE0) == 0xC0) {
      extra = 1, min = 0x80, cp = c & 0x1F;
    } else if ((c & 0xF0) == 0xE0) {
      extra = 2, min = 0x800, cp = c & 0x0F;
    } else if ((c & 0xF8) == 0xF0) {
      extra = 3, min = 0x10000, cp = c & 0x07;
    } else {
      return false;
    }
    if (i + static_cast<size_t>(extra) >= text.size()) return false;
    for (int k = 1; k <= extra; ++k) {
      const auto d = static_cast<unsigned char>(text[i + static_cast<size_t>(k)]);
      if ((d & 0xC0) != 0x80) return false;
      cp = (cp << 6) | (d & 0x3F);
    }
    if (cp < min || cp > 0x10FFFF || (cp >= 0xD800 && cp <= 0xDFFF)) return false;
    i += static_cast<size_t>(extra) + 1;
  }
  return true;
}

/// First control character (other than '\n') in `text`, or -1.
int control_char(const std::string& text) {
  for (const char ch : text) {
    const auto c = static_cast<unsigned char>(ch);
    if ((c < 0x20 && c != '\n') || c == 0x7F) return c;
  }
  return -1;
}

/// Problems of a CSV dynid wrote: a data field that is not a finite number.
void check_csv_output(const std::string& name, const std::string& text,
                      std::vector<std::string>& problems) {
  std::istringstream lines(text);
  std::string line;
  bool header = true;
  long number = 0;
  while (std::getline(lines, line)) {
    ++number;
    if (line.empty() || line[0] == '#') continue;
    if (header) {
      header = false;
      continue;
    }
    std::istringstream fields(line);
    std::string field;
    while (std::getline(fields, field, ',')) {
      char* end = nullptr;
      const double v = std::strtod(field.c_str(), &end);
      if (end == field.c_str() || *end != '\0' || !std::isfinite(v)) {
        problems.push_back(name + " line " + std::to_string(number) + ": field '" + field +
                           "' is not a finite number");
        return;
      }
    }
  }
}

/// Problems of a JSON dynid wrote: not parseable, or a null (a non-finite number, see
/// json_number) outside the keys where the model JSON documents null.
void check_json_output(const std::string& name, const std::string& text,
                       std::vector<std::string>& problems) {
  nlohmann::json j;
  try {
    j = nlohmann::json::parse(text);
  } catch (const std::exception&) {
    problems.push_back(name + " is not valid JSON");
    return;
  }
  // nominal: a base parameter the model file gives no value for (docs/cli.md, identify).
  const std::vector<std::string> may_be_null{"parent",   "lower",  "upper",
                                             "velocity", "effort", "nominal"};
  std::function<void(const nlohmann::json&, const std::string&, const std::string&)> walk =
      [&](const nlohmann::json& v, const std::string& key, const std::string& where) {
        if (v.is_null()) {
          if (std::find(may_be_null.begin(), may_be_null.end(), key) == may_be_null.end()) {
            problems.push_back(name + ": null (non-finite number) at " + where);
          }
        } else if (v.is_object()) {
          for (auto it = v.begin(); it != v.end(); ++it) {
            walk(it.value(), it.key(), where + "/" + it.key());
          }
        } else if (v.is_array()) {
          for (size_t i = 0; i < v.size(); ++i) walk(v[i], key, where + "/" + std::to_string(i));
        } else if (v.is_number_float() && !std::isfinite(v.get<double>())) {
          problems.push_back(name + ": non-finite number at " + where);
        }
      };
  const size_t before = problems.size();
  walk(j, "", "");
  // The first few places say enough; the rest only lengthen the report.
  constexpr size_t kShown = 3;
  if (problems.size() > before + kShown) {
    const size_t more = problems.size() - before - kShown;
    problems.resize(before + kShown);
    problems.push_back(name + ": " + std::to_string(more) + " more nulls");
  }
}

std::vector<fs::path> files_under(const fs::path& dir) {
  std::vector<fs::path> files;
  for (const auto& e : fs::recursive_directory_iterator(dir)) {
    if (e.is_regular_file()) files.push_back(e.path());
  }
  std::sort(files.begin(), files.end());
  return files;
}

/// Every way `o` breaks the contract; `out_dir` holds what the run wrote.
std::vector<std::string> contract_problems(const Outcome& o, const fs::path& out_dir) {
  std::vector<std::string> p;
  if (o.hung) p.push_back("did not end within " + std::to_string(kRunLimitSeconds) + " s");
  if (o.signal != 0) p.push_back("killed by signal " + std::to_string(o.signal));
  if (!o.hung && o.signal == 0 && o.code != 0 && o.code != 1 && o.code != 2) {
    p.push_back("exit code " + std::to_string(o.code));
  }
  if (!valid_utf8(o.err)) p.push_back("stderr is not valid UTF-8");
  if (const int c = control_char(o.err); c >= 0) {
    p.push_back("stderr has control character " + std::to_string(c));
  }
  const auto files = files_under(out_dir);
  if (o.code == 0) {
    for (const auto& f : files) {
      const std::string name = fs::relative(f, out_dir.parent_path()).string();
      const std::string text = slurp(f);
      if (f.extension() == ".csv") {
        check_csv_output(name, text, p);
      } else if (f.extension() == ".json") {
        check_json_output(name, text, p);
      }
    }
  } else if (o.code > 0) {
    if (const std::string problem = error_contract_problem(o.err); !problem.empty()) {
      p.push_back(problem);
    }
    for (const auto& f : files) {
      p.push_back("failed run left " + fs::relative(f, out_dir.parent_path()).string());
    }
  }
  return p;
}

// --- Mutations -----------------------------------------------------------------------------

/// Values that break parsers and numerics: non-finite spellings, extremes, subnormals, signs,
/// empty and non-numeric text, separators, raw bytes, a BOM, control characters.
const std::vector<std::string>& hostile_values() {
  static const std::vector<std::string> v{
      "nan",   "NaN",      "-nan",  "inf",        "-inf",        "Infinity",
      "1e308", "-1e308",   "1e999", "1e155",      "1e200",       "1e-320",
      "0",     "-0",       "-1",    "2147483648", "-2147483649", "99999999999999999999999",
      "",      " ",        "abc",   "0x1p3",      "1,5",         "1;2",
      "1e",    "+",        ".",     "\"",         "\xff\xfe",    "\xef\xbb\xbf",
      "x\ny",  "\x1b[31m", "\t",    "\xc3\x28",   "1.0.0",       "--help"};
  return v;
}

/// Finite extremes and non-finite spellings for numbers inside files: the values that reach the
/// numerics (overflow in products, cancellation, division by tiny values) rather than the parser.
const std::vector<std::string>& extreme_numbers() {
  static const std::vector<std::string> v{"nan",   "inf",   "-inf",     "1e308",  "-1e308", "1e200",
                                          "1e155", "1e100", "-1e100",   "1e-320", "1e-300", "0",
                                          "-0",    "1e999", "4.9e-324", "1e20"};
  return v;
}

struct Rng {
  std::mt19937 engine;
  explicit Rng(unsigned seed) : engine(seed) {}
  size_t below(size_t n) {
    return n == 0 ? 0 : std::uniform_int_distribution<size_t>(0, n - 1)(engine);
  }
  bool chance(double p) { return std::bernoulli_distribution(p)(engine); }
  const std::string& hostile() { return hostile_values()[below(hostile_values().size())]; }
  const std::string& extreme() { return extreme_numbers()[below(extreme_numbers().size())]; }
};

/// Spans [begin, end) of the numbers in `text` (digits with sign, point and exponent).
std::vector<std::pair<size_t, size_t>> number_spans(const std::string& text) {
  std::vector<std::pair<size_t, size_t>> spans;
  size_t i = 0;
  while (i < text.size()) {
    const auto digit = [&](size_t k) {
      return k < text.size() && std::isdigit(static_cast<unsigned char>(text[k]));
    };
    if (digit(i) || ((text[i] == '-' || text[i] == '.') && digit(i + 1))) {
      const bool inside_word = i > 0 && std::isalpha(static_cast<unsigned char>(text[i - 1]));
      size_t j = i + 1;
      while (j < text.size() &&
             (digit(j) || text[j] == '.' || text[j] == 'e' || text[j] == 'E' ||
              ((text[j] == '-' || text[j] == '+') && (text[j - 1] == 'e' || text[j - 1] == 'E')))) {
        ++j;
      }
      if (!inside_word) spans.emplace_back(i, j);
      i = j;
    } else {
      ++i;
    }
  }
  return spans;
}

/// Spans of the identifiers in `text` (letters, digits, '_'; starting with a letter).
std::vector<std::pair<size_t, size_t>> word_spans(const std::string& text) {
  std::vector<std::pair<size_t, size_t>> spans;
  size_t i = 0;
  while (i < text.size()) {
    if (std::isalpha(static_cast<unsigned char>(text[i]))) {
      size_t j = i;
      while (j < text.size() &&
             (std::isalnum(static_cast<unsigned char>(text[j])) || text[j] == '_')) {
        ++j;
      }
      spans.emplace_back(i, j);
      i = j;
    } else {
      ++i;
    }
  }
  return spans;
}

std::vector<std::string> split_lines(const std::string& text) {
  std::vector<std::string> lines;
  std::istringstream s(text);
  std::string line;
  while (std::getline(s, line)) lines.push_back(line + "\n");
  return lines;
}

std::string join(const std::vector<std::string>& parts) {
  std::string out;
  for (const auto& p : parts) out += p;
  return out;
}

/// One to three random edits of a text file; `what` says which, for the report.
std::string mutate_text(std::string s, Rng& rng, std::string& what) {
  const size_t edits = 1 + rng.below(3);
  for (size_t e = 0; e < edits; ++e) {
    const size_t op = rng.below(12);
    auto lines = split_lines(s);
    switch (op) {
      case 0:
      case 1: {  // one number becomes an extreme (0) or a hostile (1) value
        const auto spans = number_spans(s);
        if (spans.empty()) break;
        const auto [b, end] = spans[rng.below(spans.size())];
        const std::string v = op == 0 ? rng.extreme() : rng.hostile();
        s.replace(b, end - b, v);
        what += " number->'" + v + "'";
        break;
      }
      case 2: {  // a number scaled to an extreme but finite value
        const auto spans = number_spans(s);
        if (spans.empty()) break;
        const auto [b, end] = spans[rng.below(spans.size())];
        s.insert(end, "e300");
        what += " number*1e300";
        break;
      }
      case 3:
        if (!s.empty()) {
          const size_t at = rng.below(s.size());
          s[at] = static_cast<char>(rng.below(256));
          what += " byte@" + std::to_string(at);
        }
        break;
      case 4:
        if (!lines.empty()) {
          lines.erase(lines.begin() + static_cast<long>(rng.below(lines.size())));
          s = join(lines);
          what += " drop-line";
        }
        break;
      case 5:
        if (!lines.empty()) {
          const size_t k = rng.below(lines.size());
          const size_t copies = 1 + rng.below(3) * 20;
          lines.insert(lines.begin() + static_cast<long>(k), copies, lines[k]);
          s = join(lines);
          what += " repeat-line*" + std::to_string(copies);
        }
        break;
      case 6:
        s = s.substr(0, rng.below(s.size() + 1));
        what += " truncate";
        break;
      case 7: {
        std::string r;
        const char* end = rng.chance(0.5) ? "\r" : "\r\n";
        for (const char c : s) c == '\n' ? r += end : r += c;
        s = r;
        what += rng.chance(0.5) ? " CR-ends" : " CRLF-ends";
        break;
      }
      case 8:
        s = "\xef\xbb\xbf" + s;
        what += " BOM";
        break;
      case 9:
        if (lines.size() > 1) {
          std::swap(lines[rng.below(lines.size())], lines[rng.below(lines.size())]);
          s = join(lines);
          what += " swap-lines";
        }
        break;
      case 10: {  // one identifier replaced by another of the file (names collide, links loop)
        const auto words = word_spans(s);
        if (words.size() < 2) break;
        const auto [b, end] = words[rng.below(words.size())];
        const auto [b2, end2] = words[rng.below(words.size())];
        const std::string other = s.substr(b2, end2 - b2);
        s.replace(b, end - b, other);
        what += " word->'" + other + "'";
        break;
      }
      default: {  // a hostile value inserted anywhere
        const std::string v = rng.hostile();
        s.insert(rng.below(s.size() + 1), v);
        what += " insert'" + v + "'";
        break;
      }
    }
  }
  return s;
}

// --- Commands ------------------------------------------------------------------------------

/// One option of a command: its valid values (empty for a flag without value).
struct Option {
  std::string name;
  std::vector<std::string> values;
  bool required = false;
};

struct Command {
  std::string name;
  std::vector<Option> options;
  std::vector<std::string> inputs;  // files in the case folder the command reads (mutable)
  int cases = 0;
};

/// Planar2 reference, one 2-s period at 200 Hz: q1 = 0.6 sin(wt), q2 = 0.4 sin(2wt) + 0.3 cos(wt)
/// (w = pi rad/s), with analytic dq and ddq. Also serves as the states file of inverse-dynamics.
std::string reference_csv() {
  std::ostringstream s;
  s.precision(17);
  s << "t,q1,q2,dq1,dq2,ddq1,ddq2\n";
  const double w = M_PI;
  for (int k = 0; k < 400; ++k) {
    const double t = k / 200.0;
    s << t << ',' << 0.6 * std::sin(w * t) << ','
      << 0.4 * std::sin(2 * w * t) + 0.3 * std::cos(w * t) << ',' << 0.6 * w * std::cos(w * t)
      << ',' << 0.8 * w * std::cos(2 * w * t) - 0.3 * w * std::sin(w * t) << ','
      << -0.6 * w * w * std::sin(w * t) << ','
      << -1.6 * w * w * std::sin(2 * w * t) - 0.3 * w * w * std::cos(w * t) << '\n';
  }
  return s.str();
}

/// The arguments of a recorded reproducer: one a line, with the escapes \\, \n, \t and \xNN so
/// that raw bytes and line breaks inside an argument survive.
std::vector<std::string> read_args(const fs::path& path) {
  std::vector<std::string> args;
  std::istringstream lines(slurp(path));
  std::string line;
  while (std::getline(lines, line)) {
    std::string arg;
    for (size_t i = 0; i < line.size(); ++i) {
      if (line[i] != '\\' || i + 1 == line.size()) {
        arg += line[i];
        continue;
      }
      const char e = line[++i];
      if (e == 'n') {
        arg += '\n';
      } else if (e == 't') {
        arg += '\t';
      } else if (e == 'x' && i + 2 < line.size()) {
        arg += static_cast<char>(std::stoi(line.substr(i + 1, 2), nullptr, 16));
        i += 2;
      } else {
        arg += e;
      }
    }
    args.push_back(arg);
  }
  return args;
}

/// The inverse of read_args: the `args` file of a reproducer.
std::string escape_args(const std::vector<std::string>& args) {
  std::string out;
  for (const auto& arg : args) {
    for (const char ch : arg) {
      const auto c = static_cast<unsigned char>(ch);
      if (c == '\\') {
        out += "\\\\";
      } else if (c == '\n') {
        out += "\\n";
      } else if (c == '\t') {
        out += "\\t";
      } else if (c < 0x20 || c >= 0x7F) {
        char hex[5];
        std::snprintf(hex, sizeof hex, "\\x%02x", c);
        out += hex;
      } else {
        out += ch;
      }
    }
    out += '\n';
  }
  return out;
}

class CliFuzz : public ::testing::Test {
 protected:
  // Inputs shared by all cases: the models, a reference, a simulated run and its identification
  // (made once by the binary itself; every later case mutates copies of them).
  static void SetUpTestSuite() {
    root_ = fs::temp_directory_path() / ("dynid_cli_fuzz_base_" + std::to_string(::getpid()));
    fs::remove_all(root_);
    fs::create_directories(root_ / "out");
    const fs::path source = DYNID_SOURCE_DIR;
    fs::copy_file(source / "examples/robots/planar2.yaml", root_ / "planar2.yaml");
    fs::copy_file(source / "tests/data/models/two_link.urdf", root_ / "two_link.urdf");
    fs::copy_file(source / "tests/data/models/wrapper.yaml", root_ / "wrapper.yaml");
    write_file(root_ / "ref.csv", reference_csv());
    const Outcome sim = run_binary(
        {"simulate", "--robot", "planar2.yaml", "--trajectory", "ref.csv", "--out", "out/run.csv",
         "--periods", "2", "--torque-noise", "0.01", "--engine", "native"},
        root_);
    base_ok_ = sim.code == 0;
    if (base_ok_) fs::rename(root_ / "out/run.csv", root_ / "run.csv");
    const Outcome id = run_binary(
        {"identify", "--robot", "planar2.yaml", "--data", "run.csv", "--out", "out/result.json"},
        root_);
    base_ok_ = base_ok_ && id.code == 0;
    if (base_ok_) fs::rename(root_ / "out/result.json", root_ / "result.json");
    base_error_ = sim.err + id.err;
  }
  static void TearDownTestSuite() { fs::remove_all(root_); }

  /// Runs the unmutated command (every listed option with its first value) and then `cases`
  /// mutated ones; every run must keep the contract.
  void fuzz(const Command& command, unsigned seed) {
    ASSERT_TRUE(base_ok_) << "could not make the base run: " << base_error_;
    // One folder per process: ctest runs of two build trees at once must not share it.
    const fs::path keep = fs::temp_directory_path() / "dynid_cli_fuzz" /
                          (command.name + "." + std::to_string(::getpid()));
    fs::remove_all(keep);
    Rng rng(seed);
    int failed = 0;
    for (int c = 0; c <= command.cases; ++c) {
      const fs::path dir = keep / ("case" + std::to_string(c));
      fs::create_directories(dir / "out");
      for (const auto& name :
           {"planar2.yaml", "two_link.urdf", "wrapper.yaml", "ref.csv", "run.csv", "result.json"}) {
        fs::copy_file(root_ / name, dir / name);
      }
      std::vector<std::string> args{command.name};
      std::string what = c == 0 ? "baseline" : "";
      // Case 0 is the baseline: all its runs must succeed cleanly. Then each case mutates one
      // input file, one option value, or both.
      const bool mutate_file = c > 0 && !command.inputs.empty() && rng.chance(0.65);
      const bool mutate_option = c > 0 && (!mutate_file || rng.chance(0.25));
      const size_t mutated_option = rng.below(command.options.size());
      for (size_t k = 0; k < command.options.size(); ++k) {
        const Option& o = command.options[k];
        const bool use = c == 0 ? o.required || !o.values.empty() : o.required || rng.chance(0.4);
        if (!use && !(mutate_option && k == mutated_option)) continue;
        args.push_back(o.name);
        if (o.values.empty()) continue;
        if (mutate_option && k == mutated_option) {
          const std::string v = rng.hostile();
          args.push_back(v);
          what += " " + o.name + "='" + v + "'";
        } else {
          args.push_back(o.values[c == 0 ? 0 : rng.below(o.values.size())]);
        }
      }
      if (mutate_file) {
        const std::string& input = command.inputs[rng.below(command.inputs.size())];
        what += " " + input + ":";
        write_file(dir / input, mutate_text(slurp(dir / input), rng, what));
      }
      const Outcome o = run_binary(args, dir);
      auto problems = contract_problems(o, dir / "out");
      if (c == 0 && o.code != 0) problems.push_back("baseline failed: " + o.err);
      if (problems.empty()) {
        fs::remove_all(dir);
        continue;
      }
      ++failed;
      std::string line = "dynid";
      for (const auto& a : args) line += " '" + a + "'";
      std::string list;
      for (const auto& p : problems) list += "\n    - " + p;
      write_file(dir / "args", escape_args(args));
      write_file(dir / "replay.sh", "cd \"$(dirname \"$0\")\" && " + std::string(DYNID_BINARY) +
                                        line.substr(5) + "\n");
      ADD_FAILURE() << command.name << " case " << c << " (" << what << "), exit " << o.code << ":"
                    << list << "\n    stderr: " << o.err.substr(0, 300)
                    << "\n    replay: " << (dir / "replay.sh").string();
    }
    std::cout << command.name << ": " << failed << " of " << command.cases + 1
              << " runs broke the contract\n";
    if (failed == 0) fs::remove_all(keep);  // only failing cases are kept, for replay
  }

  static inline fs::path root_;
  static inline bool base_ok_ = false;
  static inline std::string base_error_;
};

const std::vector<std::string> kModels{"planar2.yaml", "two_link.urdf", "wrapper.yaml"};

TEST_F(CliFuzz, Model) {
  fuzz({"model",
        {{"--robot", kModels, true},
         {"--json", {"out/model.json"}},
         {"--base", {}},
         {"--friction", {"full", "none"}}},
        {"planar2.yaml", "two_link.urdf", "wrapper.yaml"},
        100},
       101);
}

TEST_F(CliFuzz, InverseDynamics) {
  fuzz({"inverse-dynamics",
        {{"--robot", kModels, true},
         {"--in", {"ref.csv"}, true},
         {"--out", {"out/tau.csv"}, true},
         {"--no-friction", {}},
         {"--columns", {"q1=q1,q2=q2"}}},
        {"ref.csv", "planar2.yaml", "two_link.urdf"},
        60},
       102);
}

TEST_F(CliFuzz, Identify) {
  fuzz({"identify",
        {{"--robot", {"planar2.yaml"}, true},
         {"--data", {"run.csv"}, true},
         {"--out", {"out/result.json"}, true},
         {"--estimator", {"ols", "wls", "rls"}},
         {"--confidence", {"0.999", "0.95"}},
         {"--friction", {"viscous,coulomb,offset", "none", "asymmetric"}},
         {"--filter", {"auto", "none", "butterworth:4", "chebyshev:8:0.5"}},
         {"--cutoff", {"10", "0"}},
         {"--decimate", {"2", "0"}},
         {"--trim", {"10", "-1"}},
         {"--zero-velocity", {"0.01"}},
         {"--savgol", {}},
         {"--no-armature", {}},
         {"--torque-offset", {"0", "0.005"}},
         {"--filter-coulomb", {}},
         {"--stream", {}},
         {"--threads", {"2", "0"}},
         {"--columns", {"q1=q1"}}},
        {"run.csv", "planar2.yaml"},
        50},
       103);
}

TEST_F(CliFuzz, Validate) {
  fuzz({"validate",
        {{"--robot", {"planar2.yaml"}, true},
         {"--params", {"result.json"}, true},
         {"--data", {"run.csv"}, true},
         {"--json", {"out/validation.json"}},
         {"--mode", {"torque", "simulation"}},
         {"--trajectory", {"ref.csv"}},
         {"--engine", {"native", "mujoco"}},
         {"--zero-velocity", {"0.01"}}},
        {"result.json", "result.json", "run.csv", "ref.csv"},
        50},
       104);
}

TEST_F(CliFuzz, Simulate) {
  fuzz({"simulate",
        {{"--robot", {"planar2.yaml"}, true},
         {"--trajectory", {"ref.csv"}, true},
         {"--out", {"out/sim.csv"}, true},
         {"--engine", {"native", "mujoco"}},
         {"--periods", {"1", "2"}},
         {"--seed", {"7"}},
         {"--position-noise", {"0.0001", "0"}},
         {"--torque-noise", {"0.01", "0"}},
         {"--counts-per-rev", {"4096"}},
         {"--delay", {"0", "1"}},
         {"--truth", {}}},
        {"ref.csv", "planar2.yaml"},
        30},
       105);
}

TEST_F(CliFuzz, Excite) {
  fuzz({"excite",
        {{"--robot", {"planar2.yaml"}, true},
         {"--out", {"out/ref.csv"}, true},
         {"--json", {"out/excite.json"}},
         {"--harmonics", {"3", "2"}},
         {"--f0", {"0.2", "0.5"}},
         {"--rate", {"50"}},
         {"--starts", {"1"}, true},
         {"--max-evaluations", {"40"}, true},
         {"--max-time", {"1"}, true},
         {"--criterion", {"cond", "logdet"}},
         {"--velocity-limit", {"2"}},
         {"--limit-fraction", {"0.8"}},
         {"--no-rest", {}}},
        {"planar2.yaml"},
        8},
       106);
}

TEST_F(CliFuzz, Demo) {
  fuzz({"demo",
        {{"--out", {"out/demo"}, true},
         {"--robot", {"planar2"}},
         {"--periods", {"3"}, true},
         {"--native", {}},
         {"--seed", {"5"}}},
        {},
        2},
       107);
}

TEST(CliFuzzRegressions, RecordedReproducersKeepTheContract) {
  const fs::path recorded = fs::path(DYNID_SOURCE_DIR) / "fuzz/regressions/commands";
  ASSERT_TRUE(fs::is_directory(recorded)) << recorded;
  const fs::path keep =
      fs::temp_directory_path() / "dynid_cli_fuzz" / ("regressions." + std::to_string(::getpid()));
  fs::remove_all(keep);
  int replayed = 0;
  for (const auto& entry : fs::directory_iterator(recorded)) {
    if (!entry.is_directory()) continue;
    const fs::path dir = keep / entry.path().filename();
    fs::create_directories(dir);
    fs::copy(entry.path(), dir, fs::copy_options::recursive);
    fs::create_directories(dir / "out");
    const Outcome o = run_binary(read_args(dir / "args"), dir);
    const auto problems = contract_problems(o, dir / "out");
    ++replayed;
    if (problems.empty()) {
      fs::remove_all(dir);
      continue;
    }
    std::string list;
    for (const auto& p : problems) list += "\n    - " + p;
    ADD_FAILURE() << entry.path().filename().string() << " (fuzz/regressions/README.md), exit "
                  << o.code << ":" << list << "\n    stderr: " << o.err.substr(0, 300)
                  << "\n    inputs: " << dir.string();
  }
  EXPECT_GT(replayed, 0);
  if (!HasFailure()) fs::remove_all(keep);
}

}  // namespace
}  // namespace dynid
