// `ranging evaluate`: the paper's Section 4 on a reduced scene (the full one is a command, not
// a test), and the committed, generated docs/results/paper-section4.md.
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <memory>
#include <sstream>

#include "tests/scratch.hpp"

namespace fs = std::filesystem;

namespace {

struct ToolRun {
  int status;
  std::string out;
};
ToolRun run_tool(const std::string& args) {
  const std::string cmd = std::string(RANGING_TOOL) + " " + args + " 2>/dev/null";
  std::unique_ptr<FILE, int (*)(FILE*)> pipe(popen(cmd.c_str(), "r"), pclose);
  std::string out;
  char buf[4096];
  std::size_t n;
  while ((n = fread(buf, 1, sizeof buf, pipe.get())) > 0) out.append(buf, n);
  const int status = pclose(pipe.release());
  return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, out};
}

std::string slurp(const std::string& path) {
  std::ifstream in(path);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

}  // namespace

TEST(Evaluate, ReducedPaperSceneReproducesTable6AndTable5AndWritesTheDocument) {
  // The paper scene with two families, the two end distances and two repeats.
  std::string scene = slurp(std::string(RANGING_SOURCE_DIR) + "/scenes/paper-section4.yaml");
  ASSERT_FALSE(scene.empty());
  auto replace_line = [&](const std::string& key, const std::string& line) {
    const auto at = scene.find(key);
    ASSERT_NE(at, std::string::npos) << key;
    scene.replace(at, scene.find('\n', at) - at, line);
  };
  replace_line("  family: [", "  family: [M1, M3, Gold4]");
  replace_line("  distances_m: [", "  distances_m: [0.1, 1.0]");
  replace_line("  repeats: ", "  repeats: 2");
  replace_line("name: ", "name: reduced");
  const ranging::testing_support::ScratchDir scratch("evaluate_reduced", ::testing::TempDir());
  const std::string dir = scratch.str();
  std::ofstream(dir + "/reduced.yaml") << scene;
  const ToolRun r = run_tool("evaluate " + dir + "/reduced.yaml --out " + dir + " --json --quiet");
  ASSERT_EQ(r.status, 0);
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_TRUE(j["checks"]["vmax_equals_table6"]);
  EXPECT_TRUE(j["checks"]["td_within_10_percent"]);
  EXPECT_TRUE(j["checks"]["m_energy_above_gold"]);
  for (const auto& f : j["families"]) {
    EXPECT_EQ(f["decode_errors"], 0) << f["family"];
    if (f["paper"]["vmax_hz"].is_number()) {
      EXPECT_NEAR(f["vmax_hz"].get<double>(), f["paper"]["vmax_hz"].get<double>(), 0.5) << f["family"];
      EXPECT_NEAR(f["td_max_s"].get<double>() * 1e6, f["paper"]["td_max_us"].get<double>(),
                  0.1 * f["paper"]["td_max_us"].get<double>())
          << f["family"];
    }
    // Definitions, not gaps: the union of the two decoders' errors, and eq. 10's u is positive
    // for every burst the Pearson decoder got right, so a family without Pearson errors has
    // u_min > 0 (and one with u_min <= 0 has errors).
    const auto errors = f["decode_errors"].get<int>();
    const auto det = f["detector"]["decode_errors"].get<int>(), prs = f["pearson"]["decode_errors"].get<int>();
    EXPECT_GE(errors, std::max(det, prs)) << f["family"];
    EXPECT_LE(errors, det + prs) << f["family"];
    if (prs == 0) {
      EXPECT_GT(f["u_min"].get<double>(), 0.0) << f["family"];
    }
    if (f["u_min"].get<double>() <= 0.0) {
      EXPECT_GT(prs, 0) << f["family"];
    }
    EXPECT_EQ(f["td_clipped"], 0) << f["family"];
  }
  const auto& rank = j["rank_correlation"];
  for (const char* q : {"u_min (Pearson, eq. 10)", "Energy_min", "T_d-max", "v_max"}) {
    ASSERT_TRUE(rank.contains(q)) << q;
    if (rank[q]["all"].is_number()) {
      EXPECT_GE(rank[q]["all"].get<double>(), -1.0);
      EXPECT_LE(rank[q]["all"].get<double>(), 1.0);
    }
  }
  // Eqs. 7-8: rho(d_min) = 1 by definition (a burst against itself); the shape changes with
  // distance (absorption), so rho(1 m) < 1, and a Pearson coefficient stays in [-1, 1].
  for (const char* fam : {"M1", "M3", "Gold4"}) {
    const auto& v = j["rho_d"][fam];
    ASSERT_EQ(v.size(), 2u) << fam;
    EXPECT_NEAR(v[0]["rho_d"].get<double>(), 1.0, 1e-12) << fam;
    EXPECT_LT(v[1]["rho_d"].get<double>(), 1.0 - 1e-6) << fam;
    EXPECT_GT(v[1]["rho_d"].get<double>(), -1.0) << fam;
  }
  EXPECT_TRUE(fs::exists(dir + "/reduced-fig11.png"));
  const std::string md = slurp(dir + "/reduced.md");
  EXPECT_NE(md.find("| u_min (Pearson, eq. 10) | M1 | 0.129 |"), std::string::npos);
  EXPECT_NE(md.find("| quantity | family | paper | ours | ratio | Spearman"), std::string::npos);
  EXPECT_NE(md.find("## Both decoders"), std::string::npos);
  EXPECT_NE(md.find("## Why the numbers differ"), std::string::npos);
  for (const char* fig : {"fig13", "fig14", "fig15"}) {
    EXPECT_TRUE(fs::exists(dir + "/reduced-" + std::string(fig) + ".png")) << fig;
  }
}

TEST(Evaluate, CommittedDocumentIsGeneratedFromTheCommittedData) {
  const std::string root = std::string(RANGING_SOURCE_DIR) + "/docs/results/";
  const std::string md = slurp(root + "paper-section4.md");
  ASSERT_FALSE(md.empty()) << "run: ranging evaluate scenes/paper-section4.yaml";
  EXPECT_NE(md.find("Generated by `ranging evaluate scenes/paper-section4.yaml`"), std::string::npos);
  const auto summary = nlohmann::json::parse(slurp(root + "paper-section4-summary.json"));
  ASSERT_EQ(summary["families"].size(), 11u);
  for (const auto& f : summary["families"]) {
    // Every family's row in the document carries the summary's u_min and energy.
    char row[128];
    std::snprintf(row, sizeof row, "| u_min (Pearson, eq. 10) | %s | ", f["family"].get<std::string>().c_str());
    const auto at = md.find(row);
    ASSERT_NE(at, std::string::npos) << row;
    const std::string line = md.substr(at, md.find('\n', at) - at);
    char u[32];
    std::snprintf(u, sizeof u, "| %.3f |", f["u_min"].get<double>());
    EXPECT_NE(line.find(u), std::string::npos) << line;
    // Both decoders' errors are in the summary, and the union is what decode_errors counts.
    EXPECT_GE(f["decode_errors"].get<int>(), f["pearson"]["decode_errors"].get<int>());
    EXPECT_GE(f["decode_errors"].get<int>(), f["detector"]["decode_errors"].get<int>());
    EXPECT_EQ(f["measurements"].get<int>(), 100 * f["eta"].get<int>()) << "10 distances x 10 repeats";
  }
  for (const char* fig : {"fig11", "fig13", "fig14", "fig15"}) {
    EXPECT_TRUE(fs::exists(root + "paper-section4-" + std::string(fig) + ".png")) << fig;
  }
}
