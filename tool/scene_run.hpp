#pragma once
// Shared by `ranging simulate` and `ranging evaluate`: run every family of a scene, with a
// progress bar on runs longer than ~2 s, and serialize the results (CSV rows, summary JSON).
#include <nlohmann/json.hpp>

#include <string>
#include <vector>

#include "model/sim/scene_simulator.hpp"

namespace ranging::tool {

struct SceneRun {
  std::vector<Measurement> rows;
  std::vector<FamilySummary> summaries;
};

// capture_dir non-empty: every stream is written there as CSV and 32-bit float WAV.
SceneRun run_scene(SceneSimulator& sim, bool quiet, const std::string& capture_dir = "");

std::string measurements_csv(const SceneRun& run, double c);
nlohmann::json summary_json(const SceneSimulator& sim, const SceneRun& run);
std::string stages_text(const SceneSimulator& sim);

}  // namespace ranging::tool
