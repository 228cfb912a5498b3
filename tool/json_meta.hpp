#pragma once
// Every JSON object the tool prints or writes carries the version and git commit of the tool
// that made it (baked at configure time, tool/build_info.hpp.in).
#include "tool/build_info.hpp"

namespace ranging::tool {

template <class Json>
Json& stamp_build_info(Json& j) {
  j["version"] = build_info::kVersion;
  j["git_commit"] = build_info::kGitCommit;
  return j;
}

}  // namespace ranging::tool
