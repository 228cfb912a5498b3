#include "model/base/input_file.hpp"

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "model/base/error.hpp"

namespace ranging {

std::string read_input_file(const std::string& path, const std::string& what, std::size_t max_bytes) {
  namespace fs = std::filesystem;
  std::error_code ec;
  const fs::file_status st = fs::status(path, ec);
  if (!fs::exists(st)) throw InputError(path + ": cannot open the " + what + ": no such file");
  if (fs::is_directory(st)) throw InputError(path + ": is a folder; expected a " + what);
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path + ": cannot open the " + what + ": " + std::strerror(errno));
  if (fs::is_regular_file(st)) {
    const auto size = fs::file_size(path, ec);
    if (!ec && size > max_bytes) {
      throw InputError(path + ": the " + what + " has " + std::to_string(size) + " bytes; valid: at most " +
                       std::to_string(max_bytes));
    }
  }
  std::string text;
  char buf[65536];
  while (in.read(buf, sizeof buf) || in.gcount() > 0) {
    text.append(buf, static_cast<std::size_t>(in.gcount()));
    if (text.size() > max_bytes) {
      throw InputError(path + ": the " + what + " is longer than " + std::to_string(max_bytes) +
                       " bytes; valid: at most " + std::to_string(max_bytes));
    }
  }
  if (in.bad()) throw InputError(path + ": cannot read the " + what);
  return text;
}

}  // namespace ranging
