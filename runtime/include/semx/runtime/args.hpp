// Command-line flags for semx executables: `--flag value`, `--flag=value`, switches, repeatable
// flags and positionals, with generated --help and errors that name the flag.
#pragma once

#include <functional>
#include <map>
#include <stdexcept>
#include <string>
#include <vector>

namespace semx::runtime {

class ArgError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

class ArgParser {
 public:
  ArgParser(std::string program, std::string summary);

  // A flag taking a value; `value_name` shows in help ("--world FILE").
  ArgParser& option(const std::string& name, const std::string& value_name, const std::string& help,
                    std::string* out);
  ArgParser& option(const std::string& name, const std::string& value_name, const std::string& help,
                    double* out);
  ArgParser& option(const std::string& name, const std::string& value_name, const std::string& help,
                    int64_t* out);
  ArgParser& option(const std::string& name, const std::string& value_name, const std::string& help,
                    int* out);
  // A flag that may be given several times.
  ArgParser& repeated(const std::string& name, const std::string& value_name, const std::string& help,
                      std::vector<std::string>* out);
  ArgParser& flag(const std::string& name, const std::string& help, bool* out);
  // Positional arguments, in order; `required` ones must be present.
  ArgParser& positional(const std::string& name, const std::string& help, std::string* out,
                        bool required = true);

  // Parses argv. Returns false when --help was given (help already printed to stdout).
  // Throws ArgError naming the offending flag for unknown flags, missing or malformed values.
  bool parse(int argc, const char* const* argv);

  std::string help() const;

 private:
  struct Spec {
    std::string name, value_name, help;
    std::function<void(const std::string&)> set;  // null for switches
    bool* sw = nullptr;
  };
  struct Positional {
    std::string name, help;
    std::string* out;
    bool required;
  };
  ArgParser& add(Spec s);

  std::string program_, summary_;
  std::vector<Spec> specs_;
  std::vector<Positional> positionals_;
};

// Runs `body` and turns ArgError/ConfigError/other exceptions into a message on stderr and a
// non-zero exit code (2 for usage errors, 1 otherwise). Every semx main goes through it.
int run_main(const std::string& program, const std::function<int()>& body);

}  // namespace semx::runtime
