#include "model/study/sweep.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <future>
#include <limits>
#include <map>
#include <mutex>
#include <set>
#include <sstream>

#include "model/base/error.hpp"
#include "model/base/subprocess.hpp"
#include "model/config/overrides.hpp"
#include "model/config/receiver_config.hpp"
#include "model/config/yaml_reader.hpp"
#include "model/dsp/stability.hpp"
#include "model/hw/hw_generator.hpp"
#include "model/hw/hw_params.hpp"
#include "model/hw/ip_package.hpp"
#include "model/hw/realtime.hpp"
#include "model/sim/capture.hpp"
#include "model/sim/scene.hpp"
#include "model/sim/scene_simulator.hpp"

namespace ranging::study {

namespace fs = std::filesystem;
using nlohmann::json;

namespace {

std::uint64_t fnv1a(const std::string& s, std::uint64_t h = 0xcbf29ce484222325ull) {
  for (unsigned char c : s) h = (h ^ c) * 0x100000001b3ull;
  return h;
}
std::uint64_t splitmix(std::uint64_t x) {
  x += 0x9E3779B97F4A7C15ull;
  x = (x ^ (x >> 30)) * 0xBF58476D1CE4E5B9ull;
  x = (x ^ (x >> 27)) * 0x94D049BB133111EBull;
  return x ^ (x >> 31);
}
std::string hex16(std::uint64_t v) {
  char buf[17];
  std::snprintf(buf, sizeof buf, "%016llx", static_cast<unsigned long long>(v));
  return buf;
}
std::string slurp(const std::string& path) {
  std::ifstream in(path);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}
std::string fmt_number(double v) {
  if (std::abs(v - std::round(v)) < 1e-9 * std::max(1.0, std::abs(v))) {
    return std::to_string(static_cast<long long>(std::llround(v)));
  }
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.10g", v);
  return buf;
}

// The overrides of a point on the spec's scene: the base configuration, the fixed model, then
// the point's keys (configuration keys under receiver.config., scene keys without "scene.").
Overrides point_overrides(const SweepSpec& spec, const Params& params) {
  Overrides ov{{"receiver.config", spec.config_path}, {"receiver.precision", "fixed"}};
  Params sorted = params;  // the keys are distinct: their order changes nothing but messages
  std::sort(sorted.begin(), sorted.end());
  for (const auto& [k, v] : sorted) {
    if (k.rfind("scene.", 0) == 0) {
      ov.push_back({k.substr(6), v});
    } else {
      ov.push_back({"receiver.config." + k, v});
    }
  }
  return ov;
}

}  // namespace

json SweepSpec::json() const {
  nlohmann::json axes_j = nlohmann::json::array();
  for (const auto& a : axes) axes_j.push_back({{"key", a.key}, {"values", a.values}});
  nlohmann::json j{{"name", name}, {"config", config_path}, {"scene", scene_path}, {"mode", mode}, {"axes", axes_j}};
  if (mode == "random") {
    j["points"] = points;
    j["seed"] = seed;
  }
  return j;
}

std::string spec_file(yaml::Reader& top, const std::string& spec_path, const fs::path& base, const std::string& key) {
  std::string v;
  if (!top.get(key, v)) throw InputError(spec_path + ": " + key + ": missing (a file, relative to the spec)");
  fs::path p(v);
  if (p.is_relative()) p = base / p;
  p = p.lexically_normal();
  std::error_code ec;  // no throw: a name too long or unreadable is a bad input, not a crash
  if (!fs::exists(p, ec) || ec)
    top.error(key, "'" + p.string() + "' does not exist" + (ec ? " (" + ec.message() + ")" : std::string()));
  return p.string();
}

SweepSpec load_sweep_spec(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw InputError(path + ": cannot open the sweep spec");
  const std::string text = slurp(path);
  const YAML::Node root = yaml::load(text, path);
  if (!root || root.IsNull()) throw InputError(path + ": the sweep spec is empty (it needs config, scene and axes)");
  SweepSpec s;
  s.origin = path;
  yaml::Reader top(root, path, "");
  const fs::path base = fs::absolute(fs::path(path)).parent_path();
  top.get("name", s.name);
  s.config_path = spec_file(top, path, base, "config");
  s.scene_path = spec_file(top, path, base, "scene");
  top.get("mode", s.mode);
  yaml::one_of(top, "mode", s.mode, {"grid", "one-at-a-time", "random"});
  const bool has_points = top.get_range("points", s.points, 1, 100000);
  long long seed = 1;
  const bool has_seed = top.get_range("seed", seed, 0, 9.0e18);
  s.seed = static_cast<std::uint64_t>(seed);
  if (s.mode == "random" && !has_points) top.error("mode", "random needs points: N");
  if (s.mode != "random" && (has_points || has_seed)) top.error(has_points ? "points" : "seed", "only for mode: random");
  const YAML::Node axes = top.child("axes");
  if (!axes || !axes.IsSequence() || axes.size() == 0) {
    if (axes) yaml::fail(path, axes, "axes", "expected a non-empty list of {key, values | range}");
    throw InputError(path + ": axes: missing; give a list of {key, values | range}");
  }
  top.finish();

  // Each value is checked on its own against the base configuration or scene: an unknown key
  // or a value out of range is refused here, naming the spec's line.
  const ReceiverConfig base_cfg = load_receiver_config(s.config_path);
  std::set<std::string> keys;
  for (std::size_t i = 0; i < axes.size(); ++i) {
    const std::string name = "axes[" + std::to_string(i) + "]";
    yaml::Reader r(axes[i], path, name);
    Axis a;
    a.line = axes[i].Mark().line + 1;
    if (!r.get("key", a.key) || a.key.empty()) r.error("key", "missing: a configuration key (correlator_fixed.chip_bits) or scene.<key>");
    if (a.key == "scene.receiver.config" || a.key == "scene.receiver.precision" ||
        a.key.rfind("scene.receiver.config.", 0) == 0) {
      r.error("key", "'" + a.key + "' is set by the sweep (the spec's config, the fixed model); sweep the configuration's own keys");
    }
    if (!keys.insert(a.key).second) r.error("key", "'" + a.key + "' is a duplicate axis");
    const bool has_values = r.has("values"), has_range = r.has("range");
    if (has_values == has_range) r.error("key", "give values: [...] or range: {from, to, step}, one of them");
    std::vector<YAML::Node> value_nodes;
    if (has_values) {
      const YAML::Node v = r.child("values");
      if (!v.IsSequence() || v.size() == 0) yaml::fail(path, v, r.key("values"), "empty axis: give at least one value");
      for (std::size_t k = 0; k < v.size(); ++k) {
        if (!v[k].IsScalar()) yaml::fail(path, v[k], r.key("values"), "expected scalars");
        a.values.push_back(v[k].Scalar());
        value_nodes.push_back(v[k]);
      }
    } else {
      yaml::section(r, "range", [&](yaml::Reader& q) {
        double from = 0, to = 0, step = 0;
        if (!q.get("from", from) || !q.get("to", to) || !q.get("step", step)) q.error("from", "a range needs from, to and step");
        if (!(step > 0)) q.error("step", "must be > 0");
        if (to < from) q.error("to", "empty axis: to < from");
        const double n = std::floor((to - from) / step + 1e-9) + 1;
        if (n > 10000) q.error("step", "more than 10000 values");
        for (int k = 0; k < static_cast<int>(n); ++k) {
          a.values.push_back(fmt_number(from + k * step));
          value_nodes.push_back(axes[i]["range"]);
        }
      });
    }
    std::set<std::string> seen;
    for (std::size_t k = 0; k < a.values.size(); ++k) {
      if (!seen.insert(a.values[k]).second) {
        yaml::fail(path, value_nodes[k], r.key("values"), "'" + a.values[k] + "' appears twice");
      }
      try {
        if (a.key.rfind("scene.", 0) == 0) {
          (void)load_scene(s.scene_path, point_overrides(s, {{a.key, a.values[k]}}));
        } else {
          (void)parse_receiver_config(receiver_config_yaml(base_cfg), s.config_path, {{a.key, a.values[k]}});
        }
      } catch (const InputError& e) {
        // The key's own check (unknown key, type, range) refuses the spec; a combination the
        // design refuses (a coefficient that does not fit, ...) is a refused point instead.
        const std::string what = e.what();
        if (what.rfind("--set", 0) == 0) yaml::fail(path, value_nodes[k], a.key, "value '" + a.values[k] + "' refused: " + what);
      }
    }
    r.finish();
    s.axes.push_back(a);
  }
  (void)load_scene(s.scene_path, point_overrides(s, {}));  // the base point itself must load
  return s;
}

std::string point_id(const Params& params) {
  Params sorted = params;  // the same point in any axis order has the same id
  std::sort(sorted.begin(), sorted.end());
  std::string canon;
  for (const auto& [k, v] : sorted) canon += k + "=" + v + "\n";
  return hex16(splitmix(fnv1a(canon)));
}

std::vector<PointDef> sweep_points(const SweepSpec& spec) {
  std::vector<PointDef> out{{point_id({}), {}}};
  std::set<std::string> ids{out[0].id};
  auto add = [&](const Params& p) {
    const std::string id = point_id(p);
    if (ids.insert(id).second) out.push_back({id, p});
  };
  if (spec.mode == "one-at-a-time") {
    for (const auto& a : spec.axes) {
      for (const auto& v : a.values) add({{a.key, v}});
    }
  } else if (spec.mode == "grid") {
    std::vector<std::size_t> idx(spec.axes.size(), 0);
    while (true) {
      Params p;
      for (std::size_t i = 0; i < spec.axes.size(); ++i) p.push_back({spec.axes[i].key, spec.axes[i].values[idx[i]]});
      add(p);
      std::size_t i = spec.axes.size();
      while (i > 0) {
        --i;
        if (++idx[i] < spec.axes[i].values.size()) break;
        idx[i] = 0;
        if (i == 0) return out;
      }
      if (spec.axes.empty()) return out;
    }
  } else {  // random: each axis value drawn uniformly, seeded; duplicates skipped
    std::size_t combos = 1;
    for (const auto& a : spec.axes) combos = std::min<std::size_t>(combos * a.values.size(), 1u << 30);
    const std::size_t want = std::min<std::size_t>(static_cast<std::size_t>(spec.points), combos);
    for (std::uint64_t draw = 0; out.size() < want + 1 && draw < 1000 * want + 1000; ++draw) {
      Params p;
      for (std::size_t i = 0; i < spec.axes.size(); ++i) {
        const std::uint64_t r = splitmix(splitmix(spec.seed ^ (draw * 0x9E3779B97F4A7C15ull)) ^ (i + 1));
        p.push_back({spec.axes[i].key, spec.axes[i].values[r % spec.axes[i].values.size()]});
      }
      add(p);
    }
  }
  return out;
}

bool in_shard(const PointDef& p, int i, int n) {
  return static_cast<int>(std::stoull(p.id, nullptr, 16) % static_cast<std::uint64_t>(n)) == i;
}

namespace {

json jnum(double v) { return std::isfinite(v) ? json(v) : json(nullptr); }

std::mutex synth_mutex;
std::map<std::string, std::shared_ptr<std::mutex>> synth_locks;

// One synthesis target: the yosys script and how its cells are counted.
struct SynthTarget {
  const char* name;
  const char* script;  // after the reads and hierarchy
  // cell name prefix -> cost field (summed)
  std::vector<std::pair<std::string, std::string>> cells;
  std::vector<std::string> fields;
};
const std::vector<SynthTarget>& synth_targets() {
  static const std::vector<SynthTarget> t = {
      {"ice40", "synth_ice40 -dsp -top receiver_top",
       {{"SB_LUT4", "lut4"}, {"SB_DFF", "dff"}, {"SB_CARRY", "carry"}, {"SB_MAC16", "mac16"}, {"SB_RAM40", "ebr"}},
       {"lut4", "dff", "carry", "mac16", "ebr"}},
      {"ecp5", "synth_ecp5 -top receiver_top",
       {{"LUT4", "lut4"}, {"TRELLIS_FF", "ff"}, {"CCU2C", "ccu2c"}, {"MULT18X18D", "mult18"}, {"DP16KD", "ebr"},
        {"PDPW16KD", "ebr"}, {"TRELLIS_DPR16X4", "lutram"}},
       {"lut4", "ff", "ccu2c", "mult18", "ebr", "lutram"}},
      {"xilinx", "synth_xilinx -family xc7 -top receiver_top",
       {{"LUT", "lut"}, {"FD", "ff"}, {"CARRY4", "carry4"}, {"DSP48E1", "dsp48"}, {"RAMB18E1", "ramb18"},
        {"RAMB36E1", "ramb36"}, {"RAM", "lutram"}, {"SRL", "srl"}},
       {"lut", "ff", "carry4", "dsp48", "ramb18", "ramb36", "lutram", "srl"}},
  };
  return t;
}

}  // namespace

std::vector<std::string> synth_target_names() {
  std::vector<std::string> n;
  for (const auto& t : synth_targets()) n.emplace_back(t.name);
  return n;
}

namespace {

// Resources of the generated receiver top for one target (yosys), cached by the hash of the
// generated RTL, the module sources and the target's script.
json synthesize(const std::map<std::string, std::string>& files, const PointOptions& o, const SynthTarget& target) {
  std::string all = files.at("rtl/receiver_top.v");
  for (const auto& m : receiver_rtl_sources()) all += slurp(o.source_dir + "/rtl/" + m);
  // iCE40 keeps the hash of earlier sweeps (their caches stay valid); other targets add their script.
  if (std::string(target.name) != "ice40") all += target.script;
  const std::string hash = hex16(fnv1a(all));
  const std::string key = std::string(target.name) == "ice40" ? hash : hash + "." + target.name;
  std::shared_ptr<std::mutex> lock;
  {
    std::lock_guard<std::mutex> g(synth_mutex);
    auto& l = synth_locks[key];
    if (!l) l = std::make_shared<std::mutex>();
    lock = l;
  }
  std::lock_guard<std::mutex> g(*lock);
  const std::string cached = o.cache_dir + "/" + key + ".json";
  if (fs::exists(cached)) {
    json j = json::parse(slurp(cached));
    j["cached"] = true;
    return j;
  }
  const std::string work = o.cache_dir + "/" + key + ".work";
  fs::remove_all(work);
  fs::create_directories(work);
  for (const auto& [name, text] : files) {
    if (name.rfind("rtl/", 0) != 0) continue;
    std::ofstream(work + "/" + fs::path(name).filename().string()) << text;
  }
  std::string cmd = "cd '" + work + "' && nice yosys -q -l yosys.log -p '";
  for (const auto& m : receiver_rtl_sources()) cmd += "read_verilog -defer " + o.source_dir + "/rtl/" + m + "; ";
  cmd += "read_verilog -defer -I. receiver_top.v; hierarchy -top receiver_top; " + std::string(target.script) +
         "; tee -q -o stat.txt stat' > /dev/null 2>&1";
  const auto t0 = std::chrono::steady_clock::now();
  if (run_shell(cmd) != 0) {
    return json{{"synth_error", std::string("yosys (") + target.name + ") failed: see " + work + "/yosys.log"}};
  }
  json j{{"rtl_hash", hash}};
  for (const auto& f : target.fields) j[f] = 0;
  std::istringstream stat(slurp(work + "/stat.txt"));
  std::string line;
  while (std::getline(stat, line)) {
    std::istringstream ls(line);
    std::string cell;
    long long n = 0;
    if (!(ls >> cell >> n)) continue;
    for (const auto& [prefix, field] : target.cells) {
      if (cell.rfind(prefix, 0) == 0) {
        j[field] = j[field].get<long long>() + n;
        break;
      }
    }
  }
  j["synth_seconds"] = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  write_file_atomic(cached, j.dump(2) + "\n");
  fs::remove_all(work);
  j["cached"] = false;
  return j;
}

// The design's own throughput rule (model/hw/realtime.hpp: bandpass, bank back end, combiner
// and peak detector against clock_hz / fs).
json throughput(const ReceiverDesign& d) {
  const RealTimeBudget r = realtime_budget(d);
  return json{{"clocks_per_sample_available", r.clocks_per_sample},
              {"clocks_per_sample_needed", r.needed_clocks_per_sample()},
              {"bank_back_end_clocks_per_group", r.bank_back_end_clocks},
              {"combiner_clocks_per_group", r.combiner_clocks},
              {"detector_clocks_per_group", r.detector_clocks},
              {"group_clocks", r.group_clocks},
              {"decimation", r.decimation},
              {"real_time", r.real_time},
              {"real_time_summary", r.summary()},
              {"rule", "model/hw/realtime.hpp: 6 <= clock_hz / fs, bank back end, combiner and peak detector <= DECIM clock_hz / fs per group"}};
}

long long word_bits(const ReceiverConfig& c) {
  const auto& b = c.bandpass;
  const auto& k = c.correlator;
  return b.input_bits + b.coef_bits + b.data_bits + b.acc_bits + k.lo_bits + k.mix_bits + k.tap_bits + k.chip_bits +
         k.corr_bits + k.weight_bits + k.score_bits + c.detector.frac_bits;
}

}  // namespace

struct FloatReferenceCache::Impl {
  using Rows = std::shared_ptr<const std::vector<Measurement>>;
  std::mutex mutex;
  std::map<std::string, std::shared_future<Rows>> rows;
  std::size_t hits = 0, misses = 0;
  // The rows of key: computed by make in the first caller's thread (its exception too, which
  // every caller of the key gets), waited for by the others; shared: whether they were already there.
  Rows get(const std::string& key, const std::function<std::vector<Measurement>()>& make, bool& shared) {
    std::promise<Rows> mine;
    std::shared_future<Rows> f;
    {
      std::lock_guard<std::mutex> lock(mutex);
      const auto it = rows.find(key);
      shared = it != rows.end();
      if (shared) {
        ++hits;
        f = it->second;
      } else {
        ++misses;
        f = mine.get_future().share();
        rows.emplace(key, f);
      }
    }
    if (!shared) {
      try {
        mine.set_value(std::make_shared<const std::vector<Measurement>>(make()));
      } catch (...) {
        mine.set_exception(std::current_exception());
      }
    }
    return f.get();
  }
};
FloatReferenceCache::FloatReferenceCache() : impl(std::make_unique<Impl>()) {}
FloatReferenceCache::~FloatReferenceCache() = default;
std::size_t FloatReferenceCache::hits() const {
  std::lock_guard<std::mutex> lock(impl->mutex);
  return impl->hits;
}
std::size_t FloatReferenceCache::misses() const {
  std::lock_guard<std::mutex> lock(impl->mutex);
  return impl->misses;
}

std::string float_reference_key(const Scene& scene) {
  Scene s = scene;
  s.receiver.precision = "float";
  ReceiverConfig& c = s.receiver.config;
  const ReceiverConfig d;  // the defaults of the keys the float model does not read
  c.name = d.name;
  c.bandpass = d.bandpass;
  c.correlator = d.correlator;
  c.detector.frac_bits = d.detector.frac_bits;
  c.clock_hz = d.clock_hz;
  c.system = d.system;
  c.allow_out_of_spec = d.allow_out_of_spec;
  return effective_scene_yaml(s, "config.yaml") + "\n--- config.yaml\n" + receiver_config_yaml(c);
}

json evaluate_point(const SweepSpec& spec, const PointDef& point, const PointOptions& options) {
  json params = json::object();
  for (const auto& [k, v] : point.params) params[k] = v;
  json out{{"id", point.id}, {"params", params}, {"default", point.params.empty()}};
  try {
    Scene scene = load_scene(spec.scene_path, point_overrides(spec, point.params));
    if (scene.moved_clock_from_hz) {  // the point's clock would not be the one evaluated
      std::ostringstream os;
      os.precision(9);
      os << "hardware.clock_hz: " << *scene.moved_clock_from_hz << " is not a multiple of the scene's sample_rate "
         << scene.fs << " (a scene would move the receiver's clock to " << scene.receiver.config.clock_hz
         << "; a sweep point keeps the clock it asks for)";
      throw InputError(os.str());
    }
    const ReceiverDesign design = design_receiver(scene.receiver.config);
    check_generatable(design);
    // Fixed model, timed.
    SceneSimulator fixed(scene);
    std::vector<Measurement> rows;
    std::size_t fa_total = 0, samples = 0;
    std::uint64_t overflows = 0;
    double u_min = std::numeric_limits<double>::infinity();
    const auto t0 = std::chrono::steady_clock::now();
    for (const auto& f : scene.excitation.families) {
      std::size_t fa = 0;
      std::uint64_t ovf = 0;
      auto r = fixed.run(f, {}, [&](const CaptureStream& c) { samples += c.volts->size(); }, &fa, &ovf);
      const FamilySummary s = summarize(scene, f, r, fa);
      if (std::isfinite(s.u_min)) u_min = std::min(u_min, s.u_min);
      fa_total += fa;
      overflows += ovf;
      rows.insert(rows.end(), r.begin(), r.end());
    }
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    // Float reference (shared by the points that differ only in what the float model ignores).
    auto run_float = [&] {
      Scene fscene = scene;
      fscene.receiver.precision = "float";
      SceneSimulator flt(fscene);
      std::vector<Measurement> r;
      for (const auto& f : scene.excitation.families) {
        auto fr = flt.run(f);
        r.insert(r.end(), fr.begin(), fr.end());
      }
      return r;
    };
    bool float_cached = false;
    const FloatReferenceCache::Impl::Rows float_rows =
        options.float_cache ? options.float_cache->impl->get(float_reference_key(scene), run_float, float_cached)
                            : std::make_shared<const std::vector<Measurement>>(run_float());
    const std::vector<Measurement>& frows = *float_rows;
    std::size_t wrong = 0, missed = 0, correct = 0, disagree = 0;
    double se = 0, max_err = 0, tof_dev = 0;
    for (std::size_t i = 0; i < rows.size(); ++i) {
      const Measurement& m = rows[i];
      if (!m.detected) {
        ++missed;
      } else if (m.det.code != m.code_sent) {
        ++wrong;
      } else {
        ++correct;
        se += m.error_m * m.error_m;
        max_err = std::max(max_err, std::abs(m.error_m));
      }
      const Measurement& f = frows.at(i);
      if (m.detected && f.detected && m.det.code == f.det.code) {
        tof_dev = std::max(tof_dev, std::abs(m.det.tof_s - f.det.tof_s));
      } else if (m.detected != f.detected || m.det.code != f.det.code) {
        ++disagree;
      }
    }
    const double nan = std::numeric_limits<double>::quiet_NaN();
    out["accuracy"] = {{"measurements", rows.size()},
                       {"decode_errors", wrong + missed + fa_total},
                       {"wrong_code", wrong},
                       {"missed", missed},
                       {"false_alarms", fa_total},
                       {"distance_rmse_m", jnum(correct ? std::sqrt(se / static_cast<double>(correct)) : nan)},
                       {"max_abs_error_m", jnum(correct ? max_err : nan)},
                       {"tof_max_deviation_from_float_s", tof_dev},
                       {"float_disagreements", disagree},
                       {"u_min", jnum(u_min)},
                       {"overflows", overflows}};
    json cost = throughput(design);
    cost["word_bits"] = word_bits(scene.receiver.config);
    if (options.synth) {
      const auto files = generate_hardware_files(design, "sweep " + spec.name);
      for (const auto& t : synth_targets()) {
        if (std::find(options.targets.begin(), options.targets.end(), t.name) == options.targets.end()) continue;
        json syn = synthesize(files, options, t);
        syn.erase("cached");
        syn.erase("synth_seconds");
        cost[t.name] = syn;
      }
    }
    out["cost"] = cost;
    // The stability guard's verdict (model/dsp/stability.hpp); a design it refuses never gets
    // here unless the scene allows out-of-spec designs.
    const DesignGuard guard = check_quantized_design(design);
    out["stability"] = {{"stable", guard.stable}, {"within_spec", guard.within_spec},
                        {"max_quantized_pole_radius", jnum(guard.max_quantized_radius())},
                        {"failures", guard.failures}};
    out["speed"] = {{"fixed_samples_per_s", seconds > 0 ? static_cast<double>(samples) / seconds : 0.0},
                    {"samples", samples},
                    {"float_reference", float_cached ? "shared" : "computed"}};
    out["status"] = "ok";
  } catch (const InputError& e) {
    out["status"] = "refused";
    out["error"] = e.what();
  }
  return out;
}

namespace {

double cost_of(const json& p) {
  const json& c = p.at("cost");
  if (c.contains("ice40") && c["ice40"].contains("lut4")) return c["ice40"]["lut4"].get<double>();
  return c.at("word_bits").get<double>();
}
double rmse_of(const json& p) {
  const json& v = p.at("accuracy").at("distance_rmse_m");
  return v.is_null() ? std::numeric_limits<double>::infinity() : v.get<double>();
}
double errors_of(const json& p) { return p.at("accuracy").at("decode_errors").get<double>(); }

void front(std::vector<json>& points, const std::string& flag, double (*b)(const json&)) {
  for (auto& p : points) {
    if (p.at("status") != "ok") {
      p[flag] = false;
      continue;
    }
    const double pa = cost_of(p), pb = b(p);
    bool dominated = false;
    for (const auto& q : points) {
      if (&q == &p || q.at("status") != "ok") continue;
      const double qa = cost_of(q), qb = b(q);
      if (qa <= pa && qb <= pb && (qa < pa || qb < pb)) {
        dominated = true;
        break;
      }
    }
    p[flag] = !dominated && std::isfinite(pb);
  }
}

std::string cost_name(const std::vector<json>& points) {
  for (const auto& p : points) {
    if (p.at("status") == "ok") {
      return p["cost"].contains("ice40") && p["cost"]["ice40"].contains("lut4") ? "lut4" : "word_bits";
    }
  }
  return "word_bits";
}

std::string cell(const json& v) {
  if (v.is_null()) return "";
  if (v.is_string()) return v.get<std::string>();
  if (v.is_boolean()) return v.get<bool>() ? "true" : "false";
  if (v.is_number_float()) {
    char buf[64];
    std::snprintf(buf, sizeof buf, "%.9g", v.get<double>());
    return buf;
  }
  return v.dump();
}

std::string csv_quote(const std::string& s) {
  if (s.find_first_of(",\"\n") == std::string::npos) return s;
  std::string o = "\"";
  for (char c : s) o += c == '"' ? std::string("\"\"") : std::string(1, c);
  return o + "\"";
}

}  // namespace

void mark_pareto(std::vector<json>& points) {
  front(points, "pareto", rmse_of);
  front(points, "pareto_errors", errors_of);
}

json sweep_document(const SweepSpec& spec, const std::vector<json>& points) {
  json pts = json::array();
  for (auto p : points) {
    pts.push_back(p);
  }
  return json{{"spec", spec.json()}, {"cost_for_front", cost_name(points)}, {"points", pts}};
}

std::string points_csv(const std::vector<json>& points) {
  std::set<std::string> keys_set;
  std::vector<std::string> keys;
  for (const auto& p : points) {
    for (const auto& [k, v] : p.at("params").items()) {
      if (keys_set.insert(k).second) keys.push_back(k);
    }
  }
  const std::vector<std::string> acc = {"measurements", "decode_errors", "wrong_code", "missed", "false_alarms",
                                        "distance_rmse_m", "max_abs_error_m", "tof_max_deviation_from_float_s",
                                        "float_disagreements", "u_min", "overflows"};
  const std::vector<std::string> cost = {"clocks_per_sample_needed", "clocks_per_sample_available",
                                         "bank_back_end_clocks_per_group", "combiner_clocks_per_group",
                                         "detector_clocks_per_group",
                                         "group_clocks", "real_time", "word_bits"};
  // Synthesis columns: every field of every target some point was synthesized for.
  std::vector<std::pair<std::string, std::string>> syn_cols;
  for (const auto& t : synth_targets()) {
    const bool any = std::any_of(points.begin(), points.end(), [&](const json& p) {
      return p.at("status") == "ok" && p["cost"].contains(t.name);
    });
    if (any || std::string(t.name) == "ice40") {
      for (const auto& f : t.fields) syn_cols.emplace_back(t.name, f);
    }
  }
  std::ostringstream os;
  os << "id,default,status";
  for (const auto& k : keys) os << "," << k;
  for (const auto& k : acc) os << "," << k;
  for (const auto& k : cost) os << "," << k;
  for (const auto& [t, k] : syn_cols) os << "," << t << "_" << k;
  os << ",stable,max_pole_radius,pareto,pareto_errors,error\n";
  for (const auto& p : points) {
    os << p.at("id").get<std::string>() << "," << cell(p.at("default")) << "," << p.at("status").get<std::string>();
    for (const auto& k : keys) os << "," << (p["params"].contains(k) ? csv_quote(cell(p["params"][k])) : "");
    const bool ok = p.at("status") == "ok";
    for (const auto& k : acc) os << "," << (ok ? cell(p["accuracy"][k]) : "");
    for (const auto& k : cost) os << "," << (ok ? cell(p["cost"][k]) : "");
    for (const auto& [t, k] : syn_cols) {
      os << "," << (ok && p["cost"].contains(t) && p["cost"][t].contains(k) ? cell(p["cost"][t][k]) : "");
    }
    const bool has_stab = ok && p.contains("stability");
    os << "," << (has_stab ? cell(p["stability"]["stable"]) : "") << ","
       << (has_stab ? cell(p["stability"]["max_quantized_pole_radius"]) : "");
    os << "," << cell(p.value("pareto", json(false))) << "," << cell(p.value("pareto_errors", json(false))) << ","
       << csv_quote(p.value("error", std::string()));
    os << "\n";
  }
  return os.str();
}

std::string summary_markdown(const SweepSpec& spec, const std::vector<json>& points) {
  std::ostringstream os;
  const std::string cname = cost_name(points);
  std::size_t ok = 0, refused = 0;
  for (const auto& p : points) (p.at("status") == "ok" ? ok : refused)++;
  os << "# Sweep " << spec.name << "\n\n"
     << "Generated by `ranging sweep " << spec.origin << "` (mode " << spec.mode << ", " << spec.axes.size()
     << " axes): " << points.size() << " points, " << ok << " evaluated, " << refused << " refused.\n"
     << "Base configuration `" << spec.config_path << "`, scene `" << spec.scene_path << "`, fixed model.\n\n"
     << "Cost for the fronts: `" << cname << "`"
     << (cname == "lut4" ? " (yosys synth_ice40 -dsp of the generated receiver top)"
                         : " (sum of the configured word lengths: a proxy, run without --no-synth for LUT4)")
     << ".\n\n## Points on a Pareto front\n\n"
     << "| id | params | " << cname
     << " | decode errors (wrong/missed/false) | RMSE mm | max mm | clocks/sample | real time | front |\n"
     << "|---|---|---|---|---|---|---|---|---|\n";
  auto row = [&](const json& p) {
    std::string params;
    for (const auto& [k, v] : p["params"].items()) params += (params.empty() ? "" : ", ") + k + "=" + cell(v);
    if (params.empty()) params = "(default)";
    const auto& a = p["accuracy"];
    char buf[512];
    std::snprintf(buf, sizeof buf, "| %s | %s | %.0f | %lld (%lld/%lld/%lld) | %s | %s | %.2f / %d | %s | %s%s |\n",
                  p["id"].get<std::string>().c_str(), params.c_str(), cost_of(p), a["decode_errors"].get<long long>(),
                  a["wrong_code"].get<long long>(), a["missed"].get<long long>(), a["false_alarms"].get<long long>(),
                  a["distance_rmse_m"].is_null() ? "--" : (std::to_string(a["distance_rmse_m"].get<double>() * 1e3)).c_str(),
                  a["max_abs_error_m"].is_null() ? "--" : (std::to_string(a["max_abs_error_m"].get<double>() * 1e3)).c_str(),
                  p["cost"]["clocks_per_sample_needed"].get<double>(), p["cost"]["clocks_per_sample_available"].get<int>(),
                  p["cost"]["real_time"].get<bool>() ? "yes" : "NO", p.value("pareto", false) ? "rmse " : "",
                  p.value("pareto_errors", false) ? "errors" : "");
    os << buf;
  };
  const json* def = nullptr;
  for (const auto& p : points) {
    if (p.at("default").get<bool>()) def = &p;
    if (p.at("status") == "ok" && (p.value("pareto", false) || p.value("pareto_errors", false))) row(p);
  }
  os << "\n## The default configuration\n\n";
  if (def && def->at("status") == "ok") {
    os << "| id | params | " << cname << " | decode errors | RMSE mm | max mm | clocks/sample | real time | front |\n"
       << "|---|---|---|---|---|---|---|---|---|\n";
    row(*def);
    if (!def->value("pareto", false)) {
      for (const auto& p : points) {
        if (p.at("status") != "ok" || &p == def) continue;
        if (cost_of(p) <= cost_of(*def) && rmse_of(p) <= rmse_of(*def) &&
            (cost_of(p) < cost_of(*def) || rmse_of(p) < rmse_of(*def))) {
          os << "\nDominated on (" << cname << ", RMSE) by " << p["id"].get<std::string>() << ".\n";
          break;
        }
      }
    }
  } else {
    os << "The default point was not evaluated" << (def ? ": " + def->value("error", std::string()) : std::string()) << "\n";
  }
  if (refused) {
    os << "\n## Refused points\n\n";
    for (const auto& p : points) {
      if (p.at("status") == "ok") continue;
      std::string params;
      for (const auto& [k, v] : p["params"].items()) params += (params.empty() ? "" : ", ") + k + "=" + cell(v);
      os << "- " << p["id"].get<std::string>() << " (" << params << "): " << p.value("error", std::string()) << "\n";
    }
  }
  os << "\n## Fixed model speed\n\n";
  for (const auto& p : points) {
    if (p.at("status") == "ok" && p.contains("speed")) {
      char buf[128];
      std::snprintf(buf, sizeof buf, "- %s: %.3g samples/s\n", p["id"].get<std::string>().c_str(),
                    p["speed"]["fixed_samples_per_s"].get<double>());
      os << buf;
    }
  }
  return os.str();
}

void write_sweep_outputs(const std::string& dir, const SweepSpec& spec, const std::vector<json>& points) {
  write_file_atomic(dir + "/sweep.json", sweep_document(spec, points).dump(2) + "\n");
  write_file_atomic(dir + "/points.csv", points_csv(points));
  write_file_atomic(dir + "/summary.md", summary_markdown(spec, points));
}

}  // namespace ranging::study
