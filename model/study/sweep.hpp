#pragma once
// Design-space sweeps (issue 11, docs/design-space.md): a spec names a base receiver
// configuration, a scene and axes (a --set key with a list or a range of values); the axes
// combine as a full grid, one at a time around the base, or N seeded random points. Each point
// is the scene run in the fixed model (and the float model as the ToF reference) with the
// point's overrides, plus its hardware cost: the design's throughput rule (clocks per sample
// against clock_hz / fs) and, optionally, iCE40 resources from yosys synth_ice40 of the
// generated receiver top, cached by the hash of the generated RTL.
//
// A point's id is a stable hash (FNV-1a 64) of its parameters: its shard (--shard I/N) and its
// result never depend on its place in the sweep (the scene's noise draws do not either,
// model/sim/scene_simulator.cpp). Results are deterministic except the measured speed.
#include <nlohmann/json.hpp>

#include <cstdint>
#include <filesystem>
#include <functional>
#include <memory>
#include <string>
#include <utility>
#include <vector>

namespace ranging::yaml {
class Reader;
}  // namespace ranging::yaml
namespace ranging {
struct Scene;
}  // namespace ranging

namespace ranging::study {

struct Axis {
  std::string key;                  // a configuration key, or "scene.<key>" for the scene
  std::vector<std::string> values;  // YAML scalars, in the spec's order
  int line = 0;                     // of the axis in the spec
};

struct SweepSpec {
  std::string origin;        // the spec file, as given
  std::string name = "sweep";
  std::string config_path;   // absolute
  std::string scene_path;    // absolute
  std::string mode = "grid"; // grid | one-at-a-time | random
  int points = 0;            // random: how many
  std::uint64_t seed = 1;    // random: the sampling seed
  std::vector<Axis> axes;
  nlohmann::json json() const;  // canonical (paths as given in the spec are not kept: absolute)
};

// Strict: unknown keys, a value the configuration (or scene) refuses, an empty axis, duplicate
// axes and a bad mode are InputErrors naming "file:line: key".
SweepSpec load_sweep_spec(const std::string& path);

// A spec's file key (config, scene): the path it names, relative to the folder `base` of the
// spec file `spec_path`, normalized. InputError when the key is missing or the file does not exist.
std::string spec_file(yaml::Reader& top, const std::string& spec_path, const std::filesystem::path& base,
                      const std::string& key);

using Params = std::vector<std::pair<std::string, std::string>>;  // axis order

struct PointDef {
  std::string id;       // 16 hex digits, stable hash of params
  Params params;        // empty: the base (default) configuration
};

std::string point_id(const Params& params);
// The points of the spec, in their canonical order: the base first, then the combination's.
std::vector<PointDef> sweep_points(const SweepSpec& spec);
// Whether the point belongs to shard i of n (by its id's hash).
bool in_shard(const PointDef& p, int i, int n);

// The float model's rows of a sweep's points (the ToF reference every point is compared with),
// keyed by everything the float model reads: the effective scene and the receiver configuration
// less its fixed-point word lengths, detector.frac_bits, hardware.clock_hz, system keys and name
// (float_reference_key). Points that differ only in those (a word-length sweep, `ranging
// wordlength`) share one float run. Thread-safe: a key is computed once even when points run in
// parallel, the others wait for it. Results are identical with and without it.
class FloatReferenceCache {
 public:
  FloatReferenceCache();
  ~FloatReferenceCache();
  FloatReferenceCache(const FloatReferenceCache&) = delete;
  FloatReferenceCache& operator=(const FloatReferenceCache&) = delete;
  std::size_t hits() const;
  std::size_t misses() const;
  struct Impl;
  std::unique_ptr<Impl> impl;
};

struct PointOptions {
  bool synth = true;
  std::shared_ptr<FloatReferenceCache> float_cache;  // null: the float model runs for every point
  // Synthesis targets (synth_target_names()): ice40 (synth_ice40 -dsp: LUT4, DFF, carry,
  // SB_MAC16, EBR), ecp5 (synth_ecp5: LUT4, FF, CCU2C, MULT18, EBR), xilinx (synth_xilinx
  // -family xc7: LUT, FF, CARRY4, DSP48E1, RAMB18/36). The fronts use ice40's LUT4 when present.
  std::vector<std::string> targets = {"ice40"};
  std::string cache_dir;    // synthesis results by RTL hash
  std::string source_dir;   // the project (rtl/*.v)
};

std::vector<std::string> synth_target_names();

// The float-reference cache's key of a scene (see FloatReferenceCache).
std::string float_reference_key(const ranging::Scene& scene);

// {"id", "params", "default", "status": "ok" | "refused", "error", "accuracy", "cost", "speed"}.
// A configuration the model refuses is "refused" with its error, not an exception.
nlohmann::json evaluate_point(const SweepSpec& spec, const PointDef& point, const PointOptions& options);

// Sets "pareto" on every point: non-dominated on (lut4 or, without synthesis, the multiply
// count estimate, distance RMSE) and on (the same cost, decode errors); refused points false.
void mark_pareto(std::vector<nlohmann::json>& points);

// DIR/sweep.json, DIR/points.csv, DIR/summary.md (points in the given order).
void write_sweep_outputs(const std::string& dir, const SweepSpec& spec, const std::vector<nlohmann::json>& points);
nlohmann::json sweep_document(const SweepSpec& spec, const std::vector<nlohmann::json>& points);
std::string points_csv(const std::vector<nlohmann::json>& points);
std::string summary_markdown(const SweepSpec& spec, const std::vector<nlohmann::json>& points);

}  // namespace ranging::study
