#include "tool/plot.hpp"

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>

#include "model/base/subprocess.hpp"
#include "model/base/error.hpp"
#include "tool/build_info.hpp"
#include "tool/shell.hpp"

namespace ranging::tool {

void check_png_option(const std::string& option, const std::string& path) {
  namespace fs = std::filesystem;
  if (path.size() < 5 || path.substr(path.size() - 4) != ".png") {
    throw InputError("option " + option + ": '" + path + "' must name a .png file");
  }
  const fs::path parent = fs::path(path).parent_path();
  std::error_code ec;
  if (!parent.empty() && !fs::is_directory(parent, ec)) {
    throw InputError("option " + option + ": the folder '" + parent.string() + "' of '" + path + "' does not exist");
  }
  if (fs::is_directory(path, ec)) throw InputError("option " + option + ": '" + path + "' is a folder");
}

void plot_with_script(const std::string& option, const std::string& script, const nlohmann::json& data,
                      const std::string& png) {
  namespace fs = std::filesystem;
  const std::string data_path = png + ".data.json", tmp = png + ".tmp";
  {
    std::ofstream out(data_path);
    out << data.dump() << "\n";
    if (!out) throw InputError(option + ": cannot write '" + data_path + "'");
  }
  const std::string path = std::string(build_info::kSourceDir) + "/" + script;
  const std::string cmd = "/usr/bin/python3 " + shell_quote(path) + " " + shell_quote(data_path) + " " + shell_quote(tmp) + " > /dev/null";
  const int rc = run_shell(cmd);
  std::error_code ec;
  fs::remove(data_path, ec);
  if (rc != 0) {
    fs::remove(tmp, ec);
    throw InputError(option + ": '" + cmd + "' failed (matplotlib missing? scripts/install-deps.sh installs it)");
  }
  fs::rename(tmp, png, ec);
  if (ec) throw InputError(option + ": cannot write '" + png + "': " + ec.message());
}

Trace min_max_trace(const std::vector<double>& y, double x0, double dx, std::size_t buckets) {
  Trace t;
  if (y.size() <= 2 * buckets || buckets == 0) {
    for (std::size_t i = 0; i < y.size(); ++i) {
      t.x.push_back(x0 + static_cast<double>(i) * dx);
      t.y.push_back(y[i]);
    }
    return t;
  }
  const std::size_t n = y.size();
  for (std::size_t b = 0; b < buckets; ++b) {
    const std::size_t lo = b * n / buckets, hi = (b + 1) * n / buckets;
    if (lo >= hi) continue;
    const auto [mn, mx] = std::minmax_element(y.begin() + static_cast<std::ptrdiff_t>(lo),
                                              y.begin() + static_cast<std::ptrdiff_t>(hi));
    const auto i1 = static_cast<std::size_t>(std::min(mn, mx) - y.begin());
    const auto i2 = static_cast<std::size_t>(std::max(mn, mx) - y.begin());
    t.x.push_back(x0 + static_cast<double>(i1) * dx);
    t.y.push_back(y[i1]);
    t.x.push_back(x0 + static_cast<double>(i2) * dx);
    t.y.push_back(y[i2]);
  }
  return t;
}

}  // namespace ranging::tool
