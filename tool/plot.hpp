#pragma once
// Plots drawn by a matplotlib script (scripts/plot_*.py, /usr/bin/python3): the tool computes
// the numbers and writes them as JSON, the script only draws. The PNG appears under its name
// only when the script succeeded (it writes PNG.tmp, renamed into place); the data file is
// removed. Errors name the option (e.g. "option --plot: ...").
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace ranging::tool {

// Checked before any work: path ends in .png and its folder exists; else InputError
// "option OPT: ...".
void check_png_option(const std::string& option, const std::string& path);

// script: path relative to the source tree (e.g. "scripts/plot_decode.py").
void plot_with_script(const std::string& option, const std::string& script, const nlohmann::json& data,
                      const std::string& png);

// At most 2 * buckets points of y (x0 + i dx): the minimum and maximum of each bucket, in
// order, so a carrier that a plain stride would alias still shows its envelope.
struct Trace {
  std::vector<double> x, y;
};
Trace min_max_trace(const std::vector<double>& y, double x0, double dx, std::size_t buckets);

}  // namespace ranging::tool
