// `ranging sweep SPEC.yaml --out DIR` and `ranging sweep merge --out DIR SHARD_DIR...`: design-space
// sweeps (model/study/sweep.hpp, docs/design-space.md).
#include <algorithm>
#include <nlohmann/json.hpp>

#include <unistd.h>

#include <atomic>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <mutex>
#include <set>
#include <sstream>
#include <thread>

#include "model/base/subprocess.hpp"
#include "model/base/error.hpp"
#include "model/sim/capture.hpp"
#include "model/study/sweep.hpp"
#include "tool/cli.hpp"
#include "tool/commands.hpp"
#include "tool/options.hpp"

namespace ranging::tool {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;
using study::PointDef;
using study::SweepSpec;

std::string slurp(const fs::path& p) {
  std::ifstream in(p);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

std::string source_dir() {
  // The project tree (rtl/, scripts/): $RANGING_TREE, else the tree this binary was built from,
  // else the working directory.
  if (const char* env = std::getenv("RANGING_TREE"); env && *env) return fs::absolute(env).string();
  const fs::path built = RANGING_TREE;
  if (fs::exists(built / "rtl/bandpass_sos.v")) return built.string();
  return fs::current_path().string();
}

void plot(const std::string& dir) {
  const std::string script = source_dir() + "/scripts/plot_sweep.py";
  const std::string cmd = "/usr/bin/python3 '" + script + "' '" + dir + "/sweep.json' '" + dir + "/front.png' > /dev/null";
  if (run_shell(cmd) != 0) throw InputError("plot: '" + cmd + "' failed (matplotlib missing? use --no-plot)");
}

// Points of the spec in canonical order, results from `results` by id.
std::vector<json> ordered(const SweepSpec& spec, const std::map<std::string, json>& results) {
  std::vector<json> out;
  for (const auto& p : study::sweep_points(spec)) {
    if (auto it = results.find(p.id); it != results.end()) out.push_back(it->second);
  }
  return out;
}

SweepSpec spec_from_json(const json& j) {
  SweepSpec s;
  s.name = j.at("name");
  s.config_path = j.at("config");
  s.scene_path = j.at("scene");
  s.mode = j.at("mode");
  if (j.contains("points")) s.points = j["points"];
  if (j.contains("seed")) s.seed = j["seed"];
  for (const auto& a : j.at("axes")) s.axes.push_back({a.at("key"), a.at("values").get<std::vector<std::string>>(), 0});
  return s;
}

int cmd_merge(const Args& args) {
  std::string out;
  bool no_plot = false;
  std::vector<std::string> dirs;
  for (std::size_t i = 0; i < args.size(); ++i) {
    if (args[i] == "--help") {
      std::cout << "usage: ranging sweep merge --out DIR SHARD_DIR... [--no-plot]\n\n"
                   "Merge the outputs of `ranging sweep --shard I/N` runs of one spec into DIR: the same\n"
                   "sweep.json, points.csv and summary.md as a serial run. Shards of different specs, or\n"
                   "shards holding the same point, are refused.\n\noptions:\n  --out DIR\n      output folder\n"
                   "  --no-plot\n      skip DIR/front.png\n";
      return 0;
    }
    if (args[i] == "--out") {
      if (i + 1 >= args.size()) throw InputError("ranging sweep merge: option --out needs a value DIR");
      out = args[++i];
    } else if (args[i] == "--no-plot") {
      no_plot = true;
    } else if (args[i].rfind("--", 0) == 0) {
      throw InputError("ranging sweep merge: unknown option '" + args[i] + "' (see --help)");
    } else {
      dirs.push_back(args[i]);
    }
  }
  if (out.empty()) throw InputError("ranging sweep merge: option --out is required");
  if (dirs.empty()) throw InputError("ranging sweep merge: give at least one SHARD_DIR");
  json spec_j;
  std::string first;
  std::map<std::string, json> results;
  std::map<std::string, std::string> owner;
  for (const auto& d : dirs) {
    const fs::path f = fs::path(d) / "sweep.json";
    if (!fs::exists(f)) throw InputError(f.string() + ": missing (not a sweep output folder)");
    json doc;
    try {
      doc = json::parse(slurp(f));
    } catch (const json::exception& e) {
      throw InputError(f.string() + ": not valid JSON: " + e.what());
    }
    if (first.empty()) {
      spec_j = doc.at("spec");
      first = f.string();
    } else if (doc.at("spec") != spec_j) {
      throw InputError(f.string() + ": spec: differs from " + first + "'s; shards of different specs cannot be merged");
    }
    for (const auto& p : doc.at("points")) {
      const std::string id = p.at("id");
      if (owner.count(id)) {
        throw InputError(f.string() + ": point " + id + " is also in " + owner[id] + "; shards overlap");
      }
      owner[id] = f.string();
      results[id] = p;
    }
  }
  const SweepSpec spec = spec_from_json(spec_j);
  SweepSpec named = spec;
  std::vector<json> pts = ordered(spec, results);
  study::mark_pareto(pts);
  fs::create_directories(out);
  write_file_atomic(out + "/spec.json", spec_j.dump(2) + "\n");
  study::write_sweep_outputs(out, spec, pts);
  if (!no_plot) plot(out);
  std::cout << "merged " << pts.size() << " points from " << dirs.size() << " shards into " << out << "\n";
  return 0;
}

}  // namespace

int cmd_sweep(const Args& args) {
  if (!args.empty() && args[0] == "merge") return cmd_merge(Args(args.begin() + 1, args.end()));
  cli::Parser p = command_parser("sweep");
  p.positional("SPEC", "sweep spec (YAML): name, config, scene, mode, axes");
  add_output_options(p, {.out = true, .quiet = true});
  add_jobs_option(p, "points evaluated");
  p.option("--shard", "I/N", "evaluate only the points of shard I of N (a stable hash of their parameters)");
  p.option("--cache", "DIR", "synthesis cache folder, may be shared by shards (default: DIR/cache)");
  p.flag("--dry-run", "check the spec, print the ids and parameters of the points (of the shard) and exit; writes nothing");
  p.flag("--no-synth", "skip yosys synthesis (cost: the throughput rule and the word-length proxy only)");
  p.option("--synth-targets", "LIST", "comma-separated yosys targets per point: ice40 (synth_ice40 -dsp), ecp5 "
           "(synth_ecp5), xilinx (synth_xilinx -family xc7); the fronts use ice40's LUT4 when it is in the list", "ice40");
  p.flag("--no-plot", "skip DIR/front.png (no Python needed)");
  if (!p.parse(args)) return 0;
  const std::string out = p.required("--out");
  const int jobs = jobs_option(p);
  int shard_i = 0, shard_n = 1;
  if (p.has("--shard")) {
    const std::string s = *p.get("--shard");
    const auto slash = s.find('/');
    try {
      if (slash == std::string::npos) throw std::invalid_argument("no slash");
      std::size_t a = 0, b = 0;
      shard_i = std::stoi(s.substr(0, slash), &a);
      shard_n = std::stoi(s.substr(slash + 1), &b);
      if (a != slash || b != s.size() - slash - 1) throw std::invalid_argument("trailing");
    } catch (const std::exception&) {
      throw InputError("option --shard: '" + s + "' is not I/N (e.g. 0/4)");
    }
    if (shard_n < 1 || shard_i < 0 || shard_i >= shard_n) {
      throw InputError("option --shard: " + s + ": valid range is 0 <= I < N, N >= 1");
    }
  }
  std::vector<std::string> targets;
  {
    const std::string list = p.get_or("--synth-targets", "ice40");
    const auto valid = study::synth_target_names();
    std::string joined;
    for (const auto& v : valid) joined += (joined.empty() ? "" : ", ") + v;
    std::size_t a = 0;
    while (a <= list.size()) {
      const std::size_t b = std::min(list.find(',', a), list.size());
      const std::string t = list.substr(a, b - a);
      if (std::find(valid.begin(), valid.end(), t) == valid.end()) {
        throw InputError("option --synth-targets: '" + t + "': valid targets are " + joined);
      }
      if (std::find(targets.begin(), targets.end(), t) != targets.end()) {
        throw InputError("option --synth-targets: '" + t + "' is listed twice");
      }
      targets.push_back(t);
      a = b + 1;
    }
  }
  const SweepSpec spec = study::load_sweep_spec(p.positionals().at(0));  // bad specs: nothing written
  std::vector<PointDef> todo;
  for (const auto& pt : study::sweep_points(spec)) {
    if (study::in_shard(pt, shard_i, shard_n)) todo.push_back(pt);
  }
  if (p.has("--dry-run")) {
    for (const auto& pt : todo) {
      std::cout << pt.id;
      for (const auto& [k, v] : pt.params) std::cout << " " << k << "=" << v;
      std::cout << (pt.params.empty() ? " (default)\n" : "\n");
    }
    return 0;
  }
  const json spec_j = spec.json();
  std::error_code ec;
  if (fs::exists(out + "/spec.json")) {
    json old;
    try {
      old = json::parse(slurp(out + "/spec.json"));
    } catch (const json::exception&) {
    }
    if (old != spec_j) throw InputError("option --out: " + out + " holds another sweep (spec.json differs); use a new DIR");
  }
  fs::create_directories(out + "/points", ec);
  if (ec) throw InputError("option --out: cannot create '" + out + "': " + ec.message());
  const std::string cache = p.get_or("--cache", out + "/cache");
  fs::create_directories(cache, ec);
  if (ec) throw InputError("option --cache: cannot create '" + cache + "': " + ec.message());
  write_file_atomic(out + "/spec.json", spec_j.dump(2) + "\n");

  study::PointOptions opt;
  opt.synth = !p.has("--no-synth");
  opt.float_cache = std::make_shared<study::FloatReferenceCache>();  // word-length points share a float run
  opt.targets = targets;
  opt.cache_dir = fs::absolute(cache).string();
  opt.source_dir = source_dir();
  std::map<std::string, json> results;
  std::vector<const PointDef*> pending;
  for (const auto& pt : todo) {
    const fs::path f = fs::path(out) / "points" / (pt.id + ".json");
    if (fs::exists(f)) {
      try {
        json j = json::parse(slurp(f));
        // A point done before is kept when it was evaluated with the same synthesis setting
        // (every requested target present; none without synthesis).
        bool same = j.at("status") != "ok";
        if (!same) {
          same = true;
          for (const auto& t : study::synth_target_names()) {
            const bool want = opt.synth && std::find(targets.begin(), targets.end(), t) != targets.end();
            if (want && !j["cost"].contains(t)) same = false;
            if (!opt.synth && j["cost"].contains(t)) same = false;
          }
        }
        if (j.at("id") == pt.id && same) {
          results[pt.id] = j;
          continue;
        }
      } catch (const json::exception&) {
      }
    }
    pending.push_back(&pt);
  }
  const bool progress = !p.has("--quiet");
  const std::size_t kept = results.size();
  if (progress) {
    std::fprintf(stderr, "sweep %s: %zu points%s, %zu done before, %zu to run, %d job(s)\n", spec.name.c_str(),
                 todo.size(), shard_n > 1 ? (" in shard " + std::to_string(shard_i) + "/" + std::to_string(shard_n)).c_str() : "",
                 kept, pending.size(), jobs);
  }
  std::mutex m;
  std::atomic<std::size_t> next{0};
  std::size_t done = 0;
  const auto t0 = std::chrono::steady_clock::now();
  std::exception_ptr failure;
  auto worker = [&] {
    while (true) {
      const std::size_t i = next++;
      if (i >= pending.size()) return;
      json r;
      try {
        r = study::evaluate_point(spec, *pending[i], opt);
        write_file_atomic(out + "/points/" + pending[i]->id + ".json", r.dump(2) + "\n");
      } catch (...) {
        std::lock_guard<std::mutex> g(m);
        if (!failure) failure = std::current_exception();
        next = pending.size();
        return;
      }
      std::lock_guard<std::mutex> g(m);
      results[pending[i]->id] = r;
      ++done;
      if (progress) {
        const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
        const double eta = s / static_cast<double>(done) * static_cast<double>(pending.size() - done);
        const int width = 30;
        const int fill = static_cast<int>(width * static_cast<double>(done) / static_cast<double>(pending.size()));
        std::fprintf(stderr, "\r[%s%s] %zu/%zu points, %.0f s, ETA %.0f s  ", std::string(static_cast<std::size_t>(fill), '#').c_str(),
                     std::string(static_cast<std::size_t>(width - fill), '.').c_str(), done, pending.size(), s, eta);
        if (!isatty(STDERR_FILENO)) std::fprintf(stderr, "\n");
      }
    }
  };
  std::vector<std::thread> pool;
  for (int k = 0; k < std::min<int>(jobs, static_cast<int>(std::max<std::size_t>(pending.size(), 1))); ++k) pool.emplace_back(worker);
  for (auto& t : pool) t.join();
  if (progress && !pending.empty() && isatty(STDERR_FILENO)) std::fprintf(stderr, "\n");
  if (failure) std::rethrow_exception(failure);

  std::vector<json> pts = ordered(spec, results);
  study::mark_pareto(pts);
  study::write_sweep_outputs(out, spec, pts);
  if (shard_n > 1) write_file_atomic(out + "/shard.json", json{{"shard", shard_i}, {"of", shard_n}}.dump() + "\n");
  if (!p.has("--no-plot")) plot(out);
  std::size_t refused = 0;
  for (const auto& x : pts) refused += x.at("status") != "ok";
  std::cout << "sweep " << spec.name << ": " << pts.size() << " points (" << refused << " refused) in " << out
            << ": sweep.json, points.csv, summary.md" << (p.has("--no-plot") ? "" : ", front.png") << "\n";
  return 0;
}

}  // namespace ranging::tool
