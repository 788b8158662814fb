#pragma once

// Opens an HTML report of dynid in headless Chromium (Debian `chromium`, installed by
// scripts/setup) and reads back what its script recorded on the page: chart and point counts,
// charts without points and script errors (html_report.hpp, "data-*" of <body> and <section>).

#include <cstdlib>
#include <filesystem>
#include <map>
#include <regex>
#include <string>
#include <vector>

#include "support/cli_run.hpp"

namespace dynid::testing {

/// The data-* attributes of one element of the rendered page.
using Attributes = std::map<std::string, std::string>;

/// The page after its scripts ran: <body>'s attributes and each <section>'s, in page order.
struct RenderedReport {
  int exit_code = -1;
  Attributes body;
  std::vector<Attributes> sections;
  std::string log;  ///< Chromium's stderr (console errors), for failure messages
};

inline Attributes attributes_of(const std::string& tag) {
  Attributes out;
  static const std::regex kAttribute(R"re(([a-z-]+)="([^"]*)")re");
  for (auto it = std::sregex_iterator(tag.begin(), tag.end(), kAttribute);
       it != std::sregex_iterator(); ++it) {
    out[(*it)[1]] = (*it)[2];
  }
  return out;
}

/// Renders `html` with `chromium --headless --dump-dom` (no sandbox: tests run as root in CI) and
/// parses the DOM it prints. Scratch files go to `scratch`.
inline RenderedReport render_in_chromium(const std::filesystem::path& html,
                                         const std::filesystem::path& scratch) {
  const std::filesystem::path dom = scratch / "dom.html", log = scratch / "chromium.log",
                              profile = scratch / "chromium-profile";
  const std::string command =
      "chromium --headless --no-sandbox --disable-gpu --no-first-run --disable-extensions "
      "--enable-logging=stderr --user-data-dir='" +
      profile.string() + "' --dump-dom 'file://" + std::filesystem::absolute(html).string() +
      "' >'" + dom.string() + "' 2>'" + log.string() + "' </dev/null";
  RenderedReport r;
  const int status = std::system(command.c_str());
  r.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  r.log = slurp(log);
  const std::string text = slurp(dom);
  std::smatch m;
  if (std::regex_search(text, m, std::regex("<body[^>]*>"))) r.body = attributes_of(m.str());
  static const std::regex kSection("<section[^>]*>");
  for (auto it = std::sregex_iterator(text.begin(), text.end(), kSection);
       it != std::sregex_iterator(); ++it) {
    r.sections.push_back(attributes_of(it->str()));
  }
  return r;
}

}  // namespace dynid::testing
