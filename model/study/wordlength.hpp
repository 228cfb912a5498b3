#pragma once
// Word-length optimization per node (issue 11, section 3; the idea of MATLAB's fxpopt): given a
// tolerance (distance RMSE at most rmse_factor x the base configuration's, and at most
// decode_errors decode errors over the scene, fixed model), find the smallest width of each node
// greedily, one node at a time from the base value downwards (stopping at the first width that
// fails: widths are assumed monotone), then check the combination jointly and widen nodes in
// turn, one bit at a time, until it passes. coef_bits and data_bits move with their fraction
// bits (the integer bits stay the base's). Every evaluation is a sweep point
// (model/study/sweep.hpp).
#include <nlohmann/json.hpp>

#include <functional>
#include <string>
#include <vector>

#include "model/study/sweep.hpp"

namespace ranging::study {

struct WordLengthSpec {
  SweepSpec base;                   // config, scene (no axes)
  double rmse_factor = 1.1;
  int decode_errors = 0;
  std::vector<std::string> nodes;   // configuration keys; default: every width of the issue
};

// Strict YAML: name, config, scene, tolerance {rmse_factor, decode_errors}, nodes [keys].
WordLengthSpec load_wordlength_spec(const std::string& path);
std::vector<std::string> default_wordlength_nodes();

// {"tolerance", "base": point, "nodes": [{"key", "base", "min", "evaluations"}], "joint": point,
//  "joint_params": {...}, "evaluations": n}; progress(what) after every evaluation (called from
// one thread at a time). The nodes' searches (each against the base) run on `jobs` threads; the
// result does not depend on jobs (only the points' "speed" does).
nlohmann::json optimize_wordlengths(const WordLengthSpec& spec, const PointOptions& options,
                                    const std::function<void(const std::string&)>& progress = {},
                                    int jobs = 1);

}  // namespace ranging::study
