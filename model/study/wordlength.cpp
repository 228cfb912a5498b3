#include "model/study/wordlength.hpp"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <fstream>
#include <sstream>
#include <filesystem>
#include <limits>
#include <mutex>
#include <set>

#include "model/base/error.hpp"
#include "model/base/parallel.hpp"
#include "model/config/receiver_config.hpp"
#include "model/config/yaml_reader.hpp"

namespace ranging::study {

namespace fs = std::filesystem;
using nlohmann::json;

std::vector<std::string> default_wordlength_nodes() {
  return {"bandpass_fixed.input_bits", "bandpass_fixed.coef_bits", "bandpass_fixed.data_bits",
          "bandpass_fixed.acc_bits",   "correlator_fixed.lo_bits", "correlator_fixed.mix_bits",
          "correlator_fixed.tap_bits", "correlator_fixed.chip_bits", "correlator_fixed.corr_bits",
          "correlator_fixed.weight_bits", "correlator_fixed.score_bits", "detector.frac_bits"};
}

WordLengthSpec load_wordlength_spec(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw InputError(path + ": cannot open the word-length spec");
  std::stringstream ss;
  ss << in.rdbuf();
  const YAML::Node root = yaml::load(ss.str(), path);
  if (!root || root.IsNull()) throw InputError(path + ": the spec is empty (it needs config and scene)");
  WordLengthSpec w;
  w.base.origin = path;
  w.base.mode = "one-at-a-time";
  yaml::Reader top(root, path, "");
  const fs::path dir = fs::absolute(fs::path(path)).parent_path();
  top.get("name", w.base.name);
  w.base.config_path = spec_file(top, path, dir, "config");
  w.base.scene_path = spec_file(top, path, dir, "scene");
  yaml::section(top, "tolerance", [&](yaml::Reader& r) {
    r.get_range("rmse_factor", w.rmse_factor, 1.0, 100.0);
    r.get_range("decode_errors", w.decode_errors, 0, 1000000);
  });
  const auto valid = default_wordlength_nodes();
  if (top.get_list("nodes", w.nodes)) {
    if (w.nodes.empty()) top.error("nodes", "give at least one node");
    std::set<std::string> seen;
    for (const auto& n : w.nodes) {
      if (std::find(valid.begin(), valid.end(), n) == valid.end()) {
        std::string list;
        for (const auto& v : valid) list += (list.empty() ? "" : ", ") + v;
        top.error("nodes", "'" + n + "' is not a node; valid: " + list);
      }
      if (!seen.insert(n).second) top.error("nodes", "'" + n + "' appears twice");
    }
  } else {
    w.nodes = valid;
  }
  top.finish();
  (void)load_receiver_config(w.base.config_path);
  return w;
}

namespace {

// The base value of a dotted key in the configuration's full YAML.
int base_value(const std::string& cfg_yaml, const std::string& key) {
  YAML::Node n = YAML::Load(cfg_yaml);
  const auto dot = key.find('.');
  return n[key.substr(0, dot)][key.substr(dot + 1)].as<int>();
}

// The key that moves with a node (the fraction bits of coef/data words), or "".
std::string partner(const std::string& key) {
  if (key == "bandpass_fixed.coef_bits") return "bandpass_fixed.coef_frac";
  if (key == "bandpass_fixed.data_bits") return "bandpass_fixed.data_frac";
  return "";
}

}  // namespace

json optimize_wordlengths(const WordLengthSpec& spec, const PointOptions& options,
                          const std::function<void(const std::string&)>& progress, int jobs) {
  const std::string cfg_yaml = receiver_config_yaml(load_receiver_config(spec.base.config_path));
  std::atomic<int> evaluations{0};
  std::mutex progress_mutex;
  auto eval = [&](const Params& p) {
    json r = evaluate_point(spec.base, {point_id(p), p}, options);
    ++evaluations;
    if (progress) {
      std::string s;
      for (const auto& [k, v] : p) s += (s.empty() ? "" : " ") + k + "=" + v;
      std::lock_guard<std::mutex> lock(progress_mutex);
      progress(s.empty() ? "(base)" : s);
    }
    return r;
  };
  const json base = eval({});
  if (base.at("status") != "ok") throw InputError(spec.base.config_path + ": the base configuration is refused: " + base.value("error", std::string()));
  const auto& ba = base.at("accuracy");
  if (ba.at("distance_rmse_m").is_null()) throw InputError(spec.base.scene_path + ": the base configuration decodes nothing correctly");
  const double rmse_limit = spec.rmse_factor * ba.at("distance_rmse_m").get<double>();
  auto passes = [&](const json& r) {
    if (r.at("status") != "ok") return false;
    const auto& a = r.at("accuracy");
    return !a.at("distance_rmse_m").is_null() && a.at("distance_rmse_m").get<double>() <= rmse_limit &&
           a.at("decode_errors").get<int>() <= spec.decode_errors;
  };
  auto params_of = [&](const std::string& key, int bits) {
    Params p{{key, std::to_string(bits)}};
    if (const std::string f = partner(key); !f.empty()) {
      p.push_back({f, std::to_string(bits - (base_value(cfg_yaml, key) - base_value(cfg_yaml, f)))});
    }
    return p;
  };
  // Each node alone: the narrowest width that passes, stepping down from the base (the nodes
  // on `jobs` threads, each writing its own slot).
  const std::size_t count = spec.nodes.size();
  std::vector<int> minimum(count), base_bits(count), steps(count);
  parallel_items(count, static_cast<std::size_t>(std::max(jobs, 1)), [&](std::size_t i, std::size_t) {
    const std::string& key = spec.nodes[i];
    const int b = base_value(cfg_yaml, key);
    int best = b, n = 0;
    for (int v = b - 1; v >= 1; --v) {
      ++n;
      if (!passes(eval(params_of(key, v)))) break;
      best = v;
    }
    minimum[i] = best;
    base_bits[i] = b;
    steps[i] = n;
  });
  json nodes = json::array();
  for (std::size_t i = 0; i < count; ++i) {
    nodes.push_back({{"key", spec.nodes[i]}, {"base", base_bits[i]}, {"min", minimum[i]}, {"evaluations", steps[i]}});
  }
  // Jointly: widen nodes in turn until the combination passes (at worst, back to the base).
  auto joint_params = [&] {
    Params p;
    for (std::size_t i = 0; i < spec.nodes.size(); ++i) {
      for (const auto& kv : params_of(spec.nodes[i], minimum[i])) p.push_back(kv);
    }
    return p;
  };
  json joint = eval(joint_params());
  int widenings = 0;
  for (std::size_t turn = 0; !passes(joint); ++turn) {
    bool any = false;
    for (std::size_t i = 0; i < spec.nodes.size() && !passes(joint); ++i) {
      const int b = nodes[i]["base"].get<int>();
      if (minimum[i] >= b) continue;
      ++minimum[i];
      ++widenings;
      any = true;
      joint = eval(joint_params());
    }
    if (!any) break;  // everything at the base: the base passes by definition
  }
  for (std::size_t i = 0; i < spec.nodes.size(); ++i) nodes[i]["joint"] = minimum[i];
  json jp = json::object();
  for (const auto& [k, v] : joint_params()) jp[k] = std::stoi(v);
  return json{{"tolerance", {{"rmse_factor", spec.rmse_factor}, {"decode_errors", spec.decode_errors},
                             {"rmse_limit_m", rmse_limit}}},
              {"base", base}, {"nodes", nodes}, {"joint", joint}, {"joint_params", jp},
              {"joint_passes", passes(joint)}, {"widenings", widenings}, {"evaluations", evaluations.load()}};
}

}  // namespace ranging::study
