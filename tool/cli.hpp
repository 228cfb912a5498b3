#pragma once
// A small, strict command-line parser for the `ranging` subcommands.
//
// Each subcommand declares its options (for --help and for validation), then parses.
// Unknown options, missing values and out-of-range numbers throw ranging::InputError
// naming the option and its valid range; main() prints it and exits with status 2.
//
//   cli::Parser p("ranging codes", "Print the code families of the paper.");
//   p.option("--family", "NAME", "code family, e.g. M1 or Gold4");
//   p.flag("--json", "machine-readable output");
//   if (!p.parse(args)) return 0;          // --help was printed
//   bool json = p.has("--json");
#include <optional>
#include <string>
#include <vector>

namespace cli {

class Parser {
 public:
  Parser(std::string usage, std::string description);

  void flag(const std::string& name, const std::string& help);
  void option(const std::string& name, const std::string& metavar, const std::string& help,
              std::optional<std::string> default_value = std::nullopt);
  void positional(const std::string& metavar, const std::string& help, bool required = true);

  // Returns false when --help was asked for (help already printed to stdout).
  bool parse(const std::vector<std::string>& args);

  bool has(const std::string& name) const;  // flag given, or option given (not default)
  std::optional<std::string> get(const std::string& name) const;  // value or default
  std::string get_or(const std::string& name, const std::string& fallback) const;
  // The value of an option the command cannot run without: InputError "option NAME is required".
  std::string required(const std::string& name) const;
  // Every value of a repeatable option, in order (e.g. --set KEY=VALUE --set ...).
  std::vector<std::string> values(const std::string& name) const;
  // The comma-separated items of an option (--distances 0.1,0.55,1.0), value or default, in order.
  std::vector<std::string> items(const std::string& name) const;
  // ... each as a number (list_number).
  std::vector<double> number_list(const std::string& name) const;
  // Numeric options: validated to be finite and within [lo, hi]; the error names the option.
  double number(const std::string& name, double fallback, double lo, double hi) const;
  long long integer(const std::string& name, long long fallback, long long lo, long long hi) const;
  const std::vector<std::string>& positionals() const { return positionals_; }

  std::string help_text() const;

 private:
  struct Opt {
    std::string name, metavar, help;
    bool takes_value = false;
    std::optional<std::string> default_value;
  };
  struct Pos {
    std::string metavar, help;
    bool required = true;
  };
  const Opt* find(const std::string& name) const;

  std::string usage_, description_;
  std::vector<Opt> opts_;
  std::vector<Pos> pos_;
  std::vector<std::pair<std::string, std::string>> given_;  // name -> value ("" for flags)
  std::vector<std::string> positionals_;
};

// An item of a comma-separated option (Parser::items) as a number, the whole item in std::stod
// syntax; else InputError "option OPTION: 'ITEM' is not a number".
double list_number(const std::string& option, const std::string& item);

}  // namespace cli
