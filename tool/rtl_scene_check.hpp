#pragma once
// `ranging simulate --precision rtl`: every stream the fixed receiver runs in a scene
// (calibration and measurements) is collected and run through the Verilated receiver of the
// same design (tool/rtl_runner.hpp); the RTL's events must equal the fixed model's, stream by
// stream. The scene's results are the fixed model's, proven identical to the RTL's.
#include <nlohmann/json.hpp>

#include <memory>
#include <string>
#include <vector>

#include "model/sim/scene_simulator.hpp"

namespace ranging::tool {

class RtlSceneCheck {
 public:
  // simulator: RtlBuildOptions::simulator (verilator: the RTL; postsynth: the iCE40 netlist).
  RtlSceneCheck(std::string rtl_dir, std::string work_root, bool quiet, std::string simulator = "verilator");
  ~RtlSceneCheck();
  // Installs the collector on the simulator (before the scene runs).
  void attach(SceneSimulator& sim);
  // Builds the RTL of every design the scene used and compares; returns the report
  // {"streams", "events_compared", "mismatches", "first_mismatch", "pass", "designs": [...]}.
  nlohmann::json run();

 private:
  struct Group;
  std::string rtl_dir_, work_root_, simulator_;
  bool quiet_;
  std::vector<std::unique_ptr<Group>> groups_;
};

}  // namespace ranging::tool
