#pragma once
// Output files that are either complete or absent.
//
// write_file_atomic(path, content) writes content to a temporary file in the same folder
// (".NAME.tmp-XXXXXX", mkstemp), checks every write, fsyncs it and renames it over path, so
// an interrupted or failed run never leaves a partial file under the final name. If path
// already exists and is not a regular file or a folder (a character device such as /dev/null
// or /dev/full, a FIFO), it is written in place instead: replacing a device node with a file
// would be wrong, and a write error (ENOSPC on /dev/full) is still reported.
// Every failure throws InputError "PATH: cannot write: <reason>" (the tool exits with status
// 2: the output named on the command line cannot be used) and removes the temporary file.
//
// While a temporary file exists it is registered; install_output_cleanup_on_signals() makes
// SIGINT, SIGTERM and SIGHUP unlink the registered temporaries (unlink is async-signal-safe)
// and then die of the signal as they would have, so Ctrl-C leaves neither a partial output nor
// a stray temporary.
//
// check_output_file(path) and check_output_dir(dir) validate a destination before any work
// or printing: a folder where a file is wanted (or the reverse), a missing or unwritable
// parent folder are refused with the option's name.
#include <string>
#include <vector>

namespace ranging {

void write_file_atomic(const std::string& path, const std::string& content);

// `what` names the option in the message ("option --out").
void check_output_file(const std::string& path, const std::string& what);
// Creates dir (and its parents) if needed and probes that a file can be created in it.
// Returns the folders it created, outermost first (for OutputDir).
std::vector<std::string> check_output_dir(const std::string& dir, const std::string& what);

// An output folder for one run: checked and created by the constructor (check_output_dir);
// unless keep() is called, the destructor removes the folders it created if they are still
// empty, so a run that fails leaves no new folder behind.
class OutputDir {
 public:
  OutputDir(const std::string& dir, const std::string& what) : created_(check_output_dir(dir, what)) {}
  OutputDir(const OutputDir&) = delete;
  OutputDir& operator=(const OutputDir&) = delete;
  ~OutputDir();
  void keep() { created_.clear(); }

 private:
  std::vector<std::string> created_;
};

void install_output_cleanup_on_signals();

}  // namespace ranging
