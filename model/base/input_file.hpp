#pragma once
// Reading an input file named on the command line, with errors that say what went wrong:
// a missing file, a folder given where a file is expected, a read error, or a file larger
// than max_bytes. Every error is an InputError "PATH: <what> ...".
#include <cstddef>
#include <string>

namespace ranging {

// `what` names the kind of file in messages ("configuration file", "scene file").
std::string read_input_file(const std::string& path, const std::string& what, std::size_t max_bytes);

}  // namespace ranging
