// The command line as engineers expect it (issue 16, section 7): --version with the git commit
// baked at configure time, in every JSON output too; `ranging help CMD`; errors said once;
// `codes --list --json`; evaluate's output does not default into the source tree.
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>

#include "tests/process.hpp"
#include "tests/scratch.hpp"

namespace fs = std::filesystem;
using ranging::testing_support::run_command;
using ranging::testing_support::run_tool;

namespace {

std::string tool_version() {
  const auto r = run_tool("--version");
  std::smatch m;
  // the commit of the build, "-dirty" when tracked files had changes (tool/git_commit.cmake)
  static const std::regex re(
      "^ranging ([0-9]+\\.[0-9]+\\.[0-9]+) \\(git ([0-9a-f]{7,40}(-dirty|-unknown-state)?|unknown)\\)\n$");
  if (r.status != 0 || !std::regex_match(r.out, m, re)) return "";
  return m[1];
}

std::size_t count(const std::string& s, const std::string& what) {
  std::size_t n = 0;
  for (auto at = s.find(what); at != std::string::npos; at = s.find(what, at + 1)) ++n;
  return n;
}

}  // namespace

TEST(CliItems, VersionNamesTheVersionAndTheGitCommit) {
  const auto r = run_tool("--version");
  EXPECT_EQ(r.status, 0);
  EXPECT_FALSE(tool_version().empty()) << "got: " << r.out;
  // The version is the project's (CMakeLists.txt project(... VERSION x.y.z)).
  std::ifstream cm(std::string(RANGING_SOURCE_DIR) + "/CMakeLists.txt");
  std::stringstream ss;
  ss << cm.rdbuf();
  EXPECT_NE(ss.str().find("VERSION " + tool_version() + " "), std::string::npos);
}

TEST(CliItems, EveryJsonOutputCarriesVersionAndCommit) {
  const std::string v = tool_version();
  ASSERT_FALSE(v.empty());
  const ranging::testing_support::ScratchDir scratch("ranging_cli_items");
  const fs::path tmp = scratch.path() / "out";  // made by simulate
  for (const std::string& cmd : std::vector<std::string>{"codes --family M1 --json", "codes --degree 5 --json", "codes --list --json",
                                "filter --json", "demo --family M1 --distances 0.5 --json",
                                "simulate " + std::string(RANGING_SOURCE_DIR) + "/scenes/minimal.yaml --json --quiet --out " +
                                    tmp.string()}) {
    const auto r = run_tool(cmd);
    ASSERT_EQ(r.status, 0) << cmd << ": " << r.err;
    const auto j = nlohmann::json::parse(r.out);
    EXPECT_EQ(j.value("version", ""), v) << cmd;
    EXPECT_FALSE(j.value("git_commit", "").empty()) << cmd;
  }
}

TEST(CliItems, TheCommandListSeparatesEveryNameFromItsSummary) {
  // `ranging --help`: each command line is "  NAME  summary", names in one column, at least two
  // spaces after the longest (a fixed column once ran "wordlength" into its summary)
  const auto r = run_tool("--help");
  ASSERT_EQ(r.status, 0) << r.err;
  const auto at = r.out.find("commands:\n");
  ASSERT_NE(at, std::string::npos) << r.out;
  std::istringstream lines(r.out.substr(at + 10));
  static const std::regex row("^  ([a-z]+)( {2,})(\\S.*)$");
  std::size_t column = 0, rows = 0;
  bool saw_wordlength = false;
  for (std::string line; std::getline(lines, line) && !line.empty();) {
    std::smatch m;
    ASSERT_TRUE(std::regex_match(line, m, row)) << "not NAME  summary: '" << line << "'";
    const std::size_t col = 2 + m[1].length() + m[2].length();
    if (column == 0) column = col;
    EXPECT_EQ(col, column) << line;
    saw_wordlength = saw_wordlength || m[1] == "wordlength";
    ++rows;
  }
  EXPECT_GE(rows, 10u);
  EXPECT_TRUE(saw_wordlength);
}

TEST(CliItems, HelpCmdIsCmdHelp) {
  for (const char* c : {"codes", "verify", "generate", "simulate"}) {
    const auto a = run_tool(std::string("help ") + c);
    const auto b = run_tool(std::string(c) + " --help");
    EXPECT_EQ(a.status, 0) << c;
    EXPECT_EQ(a.out, b.out) << c;
    EXPECT_NE(a.out.find("usage: ranging " + std::string(c)), std::string::npos) << a.out;
  }
  const auto bad = run_tool("help nosuch");
  EXPECT_EQ(bad.status, 2);
  EXPECT_EQ(bad.out, "");
  EXPECT_NE(bad.err.find("nosuch"), std::string::npos);
}

TEST(CliItems, AnErrorIsSaidOnce) {
  for (const char* c : {"demo", "codes", "generate", "filter"}) {
    const auto r = run_tool(std::string(c) + " --bogus");
    EXPECT_EQ(r.status, 2) << c;
    EXPECT_EQ(r.out, "") << c;
    EXPECT_EQ(count(r.err, std::string("ranging ") + c), 1u) << r.err;
    EXPECT_EQ(count(r.err, "error"), 1u) << r.err;
    EXPECT_NE(r.err.find("--bogus"), std::string::npos) << r.err;
  }
}

TEST(CliItems, CodesListJsonListsEveryFamily) {
  const auto r = run_tool("codes --list --json");
  ASSERT_EQ(r.status, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  const auto text = run_tool("codes --list");
  ASSERT_TRUE(j["families"].is_array());
  EXPECT_EQ(j["families"].size(), count(text.out, "\n"));
  bool gold4 = false;
  for (const auto& f : j["families"]) {
    if (f["name"] == "Gold4") {
      gold4 = true;
      EXPECT_EQ(f["length"], 7);
      EXPECT_EQ(f["eta"], 9);
    }
  }
  EXPECT_TRUE(gold4);
}

TEST(CliItems, EvaluateWithoutOutWritesUnderOutNotDocs) {
  const ranging::testing_support::ScratchDir scratch("ranging_eval_cwd");
  const fs::path cwd = scratch.path();
  std::ifstream in(std::string(RANGING_SOURCE_DIR) + "/scenes/paper-section4.yaml");
  std::stringstream ss;
  ss << in.rdbuf();
  std::string scene = ss.str();
  auto replace_line = [&](const std::string& key, const std::string& line) {
    const auto at = scene.find(key);
    ASSERT_NE(at, std::string::npos) << key;
    scene.replace(at, scene.find('\n', at) - at, line);
  };
  replace_line("  family: [", "  family: [Gold4]");
  replace_line("  distances_m: [", "  distances_m: [0.5]");
  replace_line("  repeats: ", "  repeats: 1");
  replace_line("name: ", "name: tiny");
  std::ofstream(cwd / "tiny.yaml") << scene;
  const auto r = run_command("cd '" + cwd.string() + "' && '" + RANGING_TOOL + "' evaluate tiny.yaml --no-plots --quiet");
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_TRUE(fs::exists(cwd / "out/tiny/tiny.md"));
  EXPECT_FALSE(fs::exists(cwd / "docs"));
}

// Every command's --help: below "options:" (and "arguments:"), a line is an option or positional
// name (2 spaces) or a help text indented 6 spaces, its continuation lines too.
TEST(CliItems, HelpTextsAreIndentedUnderTheirOptions) {
  for (const char* c : {"simulate", "decode", "demo", "sweep", "verify", "generate", "bitstream", "evaluate"}) {
    const auto r = run_tool(std::string(c) + " --help");
    ASSERT_EQ(r.status, 0) << c;
    const auto at = r.out.find("\noptions:\n");
    ASSERT_NE(at, std::string::npos) << c;
    std::istringstream in(r.out.substr(at + 10));
    std::size_t lines = 0;
    for (std::string line; std::getline(in, line);) {
      if (line.empty()) continue;
      ++lines;
      EXPECT_TRUE(line.rfind("  --", 0) == 0 || line.rfind("      ", 0) == 0) << c << ": '" << line << "'";
    }
    EXPECT_GT(lines, 4u) << c;
  }
}
