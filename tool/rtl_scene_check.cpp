#include "tool/rtl_scene_check.hpp"

#include <iostream>

#include "tool/rtl_runner.hpp"

namespace ranging::tool {

struct RtlSceneCheck::Group {
  ReceiverDesign design;
  std::vector<RtlStimulus> streams;
  std::vector<std::vector<EventFixed>> expected;
};

RtlSceneCheck::RtlSceneCheck(std::string rtl_dir, std::string work_root, bool quiet, std::string simulator)
    : rtl_dir_(std::move(rtl_dir)), work_root_(std::move(work_root)), simulator_(std::move(simulator)), quiet_(quiet) {}

RtlSceneCheck::~RtlSceneCheck() = default;

void RtlSceneCheck::attach(SceneSimulator& sim) {
  sim.set_fixed_observer([this](const ReceiverDesign& d, const std::vector<std::int64_t>& x,
                                const std::vector<EventFixed>& events) {
    Group* g = nullptr;
    for (auto& p : groups_) {
      if (p->design.config.family == d.config.family && p->design.config.decimation == d.config.decimation &&
          p->design.config.cycles_per_chip == d.config.cycles_per_chip) {
        g = p.get();
      }
    }
    if (!g) {
      groups_.push_back(std::make_unique<Group>());
      g = groups_.back().get();
      g->design = d;
    }
    RtlStimulus s;
    s.name = "stream-" + std::to_string(g->streams.size());
    s.x = x;
    g->streams.push_back(std::move(s));
    g->expected.push_back(events);
  });
}

nlohmann::json RtlSceneCheck::run() {
  nlohmann::json report;
  std::uint64_t streams = 0, compared = 0, mismatches = 0;
  nlohmann::json first = nullptr;
  report["designs"] = nlohmann::json::array();
  for (const auto& g : groups_) {
    const std::string name = g->design.config.name + "-" + g->design.config.family;
    RtlBuildOptions o;
    o.rtl_dir = rtl_dir_;
    o.work_dir = work_root_.empty() ? default_work_dir("simulate", name) : std::filesystem::path(work_root_) / name;
    o.origin = "scene receiver " + name;
    o.quiet = quiet_;
    o.simulator = simulator_;
    const RtlReceiver rtl(g->design, o);
    if (!quiet_) std::cerr << "running " << g->streams.size() << " streams of " << name << " through the RTL ...\n";
    const auto results = rtl.run(g->streams);
    std::uint64_t group_mismatch = 0;
    for (std::size_t i = 0; i < results.size(); ++i) {
      const auto& got = results[i].segments.front().events;
      const auto& exp = g->expected[i];
      const std::size_t n = std::max(got.size(), exp.size());
      for (std::size_t k = 0; k < n; ++k) {
        ++compared;
        const bool ok = k < got.size() && k < exp.size() && got[k] == exp[k];
        if (ok) continue;
        ++mismatches;
        ++group_mismatch;
        if (first.is_null()) {
          auto text = [](const std::vector<EventFixed>& v, std::size_t k) {
            if (k >= v.size()) return std::string("none");
            return "{code " + std::to_string(v[k].code) + ", arrival " + std::to_string(v[k].arrival) + ", score " +
                   std::to_string(v[k].score) + ", margin " + std::to_string(v[k].margin) + "}";
          };
          first = {{"design", name}, {"stream", i}, {"event", k}, {"expected", text(exp, k)}, {"got", text(got, k)}};
        }
      }
      if (results[i].stalled) ++mismatches;
    }
    streams += results.size();
    report["designs"].push_back({{"name", name}, {"streams", results.size()}, {"mismatches", group_mismatch},
                                 {"work_dir", rtl.work_dir().string()}});
  }
  report["streams"] = streams;
  report["events_compared"] = compared;
  report["mismatches"] = mismatches;
  report["first_mismatch"] = first;
  report["pass"] = mismatches == 0 && streams > 0;
  return report;
}

}  // namespace ranging::tool
