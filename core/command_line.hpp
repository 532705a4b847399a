// The one command-line parser of the `bodyscan` commands and the benchmarks.
//
// A command declares its options, each bound to a variable it owns, then parses
// its arguments once:
//
//   CommandLine cl("bodyscan measure", kUsage);
//   cl.flag("--auto", &automatic);
//   cl.option("--floor", &floor_y);            // std::optional<double>
//   cl.positional("FILE.ply", &file);
//   if (const auto exit = cl.parse(argc, argv)) return *exit;
//
// Contract:
// - argv[0] is the command's own name and is skipped.
// - An option takes its value as the next argument or after '=' (`--port=8080`).
//   A value may begin with '-' (`--turn -20`). A flag takes no value.
// - Numbers must be whole: "12x", "", "nan" and "inf" are errors, not 12 or 0.
// - Options may repeat; a single-valued option keeps its last value.
// - Positionals fill in declaration order; `--` ends the options.
// - `-h` / `--help` prints the usage to stdout and parse() returns 0. Anything
//   wrong (an unknown option, a missing or malformed value, a positional too many
//   or missing) prints "PROGRAM: what is wrong" and the usage to stderr and parse()
//   returns 2. Otherwise parse() returns nullopt: the command runs.
#pragma once

#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace bodyscan {

class CommandLine {
 public:
  // Checks and stores an option's value; returns what is wrong with it, or "".
  using ValueParser = std::function<std::string(const std::string& value)>;

  CommandLine(std::string program, std::string usage);

  // `names` is one name or several separated by '|' ("-q|--quiet").
  void flag(std::string_view names, bool* out);
  void option(std::string_view names, std::string* out);
  void option(std::string_view names, std::optional<std::string>* out);
  void option(std::string_view names, double* out);
  void option(std::string_view names, std::optional<double>* out);
  void option(std::string_view names, float* out);
  void option(std::string_view names, int* out);
  void option(std::string_view names, std::optional<int>* out);
  void option(std::string_view names, std::uint64_t* out);
  // Each occurrence appends its value.
  void option(std::string_view names, std::vector<std::string>* out);
  void option(std::string_view names, ValueParser parse);

  void positional(std::string name, std::string* out, bool required = true);
  // Every positional after the declared ones (none may follow `rest`).
  void rest(std::string name, std::vector<std::string>* out);

  std::optional<int> parse(int argc, char** argv);
  std::optional<int> parse(const std::vector<std::string>& args);

  // A usage error found after parsing (options that conflict): prints it and the
  // usage as parse() does; returns 2, the exit code.
  int fail(const std::string& message) const;

  const std::string& program() const { return program_; }
  const std::string& usage() const { return usage_; }

 private:
  struct Option {
    std::vector<std::string> names;
    bool takes_value = true;
    std::function<void()> set_flag;
    ValueParser parse;
  };
  struct Positional {
    std::string name;
    std::string* out = nullptr;
    std::vector<std::string>* rest = nullptr;
    bool required = true;
  };

  void add(std::string_view names, bool takes_value, std::function<void()> set_flag, ValueParser parse);
  const Option* find(std::string_view name) const;
  // Parses the option at args[*i] (and its value, moving *i past it); an exit
  // code when it is wrong.
  std::optional<int> parse_option(const std::vector<std::string>& args, std::size_t* i) const;

  std::string program_;
  std::string usage_;
  std::vector<Option> options_;
  std::vector<Positional> positionals_;
};

// A value checked as an integer from `lo` to `hi` and handed to `store`.
CommandLine::ValueParser integer_between(long long lo, long long hi, std::function<void(long long)> store);

// Strict conversions, the parser's own: nullopt unless the whole text is one
// finite number (an integer for the integer forms, in range).
std::optional<double> parse_double(std::string_view text);
std::optional<long long> parse_integer(std::string_view text);
// "a,b,c" as numbers; nullopt if any is malformed, or if `count` is not 0 and
// the list has another length.
std::optional<std::vector<double>> parse_number_list(std::string_view text, std::size_t count = 0);

}  // namespace bodyscan
