#pragma once
// Every JSON object the tool prints or writes carries the version and git commit of the tool
// that made it (tool/build_info.hpp.in; the commit is written at every build).
#include "tool/build_info.hpp"

namespace ranging::tool {

template <class Json>
Json& stamp_build_info(Json& j) {
  j["version"] = build_info::kVersion;
  j["git_commit"] = build_info::git_commit();
  return j;
}

}  // namespace ranging::tool
