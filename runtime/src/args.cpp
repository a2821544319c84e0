#include "semx/runtime/args.hpp"

#include <malloc.h>

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <iostream>
#include <sstream>

#include "semx/runtime/config.hpp"

namespace semx::runtime {

ArgParser::ArgParser(std::string program, std::string summary)
    : program_(std::move(program)), summary_(std::move(summary)) {}

ArgParser& ArgParser::add(Spec s) {
  if (s.name.rfind("--", 0) != 0) s.name = "--" + s.name;
  specs_.push_back(std::move(s));
  return *this;
}

ArgParser& ArgParser::option(const std::string& name, const std::string& value_name, const std::string& help,
                             std::string* out) {
  return add({name, value_name, help, [out](const std::string& v) { *out = v; }});
}

ArgParser& ArgParser::option(const std::string& name, const std::string& value_name, const std::string& help,
                             double* out) {
  return add({name, value_name, help, [out, name](const std::string& v) {
                char* end = nullptr;
                errno = 0;
                const double d = std::strtod(v.c_str(), &end);
                if (v.empty() || *end != '\0' || errno != 0 || !std::isfinite(d)) {
                  throw ArgError("--" + name + ": '" + v + "' is not a number");
                }
                *out = d;
              }});
}

ArgParser& ArgParser::option(const std::string& name, const std::string& value_name, const std::string& help,
                             int64_t* out) {
  return add({name, value_name, help, [out, name](const std::string& v) {
                char* end = nullptr;
                errno = 0;
                const long long i = std::strtoll(v.c_str(), &end, 10);
                if (v.empty() || *end != '\0' || errno != 0) {
                  throw ArgError("--" + name + ": '" + v + "' is not an integer");
                }
                *out = i;
              }});
}

ArgParser& ArgParser::option(const std::string& name, const std::string& value_name, const std::string& help,
                             int* out) {
  return add({name, value_name, help, [out, name](const std::string& v) {
                char* end = nullptr;
                errno = 0;
                const long i = std::strtol(v.c_str(), &end, 10);
                if (v.empty() || *end != '\0' || errno != 0 || i < INT32_MIN || i > INT32_MAX) {
                  throw ArgError("--" + name + ": '" + v + "' is not an integer");
                }
                *out = static_cast<int>(i);
              }});
}

ArgParser& ArgParser::repeated(const std::string& name, const std::string& value_name,
                               const std::string& help, std::vector<std::string>* out) {
  return add({name, value_name, help, [out](const std::string& v) { out->push_back(v); }});
}

ArgParser& ArgParser::flag(const std::string& name, const std::string& help, bool* out) {
  Spec s{name, "", help, nullptr};
  s.sw = out;
  return add(std::move(s));
}

ArgParser& ArgParser::positional(const std::string& name, const std::string& help, std::string* out,
                                 bool required) {
  positionals_.push_back({name, help, out, required});
  return *this;
}

bool ArgParser::parse(int argc, const char* const* argv) {
  std::size_t next_positional = 0;
  for (int i = 1; i < argc; ++i) {
    std::string arg = argv[i];
    if (arg == "--help" || arg == "-h") {
      std::cout << help();
      return false;
    }
    if (arg.rfind("--", 0) == 0 && arg.size() > 2) {
      std::string value;
      bool has_value = false;
      const auto eq = arg.find('=');
      if (eq != std::string::npos) {
        value = arg.substr(eq + 1);
        arg = arg.substr(0, eq);
        has_value = true;
      }
      const Spec* spec = nullptr;
      for (const auto& s : specs_) {
        if (s.name == arg) spec = &s;
      }
      if (!spec) throw ArgError("unknown flag '" + arg + "' (see " + program_ + " --help)");
      if (spec->sw) {
        if (has_value) throw ArgError(arg + " takes no value");
        *spec->sw = true;
        continue;
      }
      if (!has_value) {
        if (i + 1 >= argc) throw ArgError(arg + " needs a value (" + spec->value_name + ")");
        value = argv[++i];
      }
      spec->set(value);
      continue;
    }
    if (next_positional >= positionals_.size()) {
      throw ArgError("unexpected argument '" + arg + "' (see " + program_ + " --help)");
    }
    *positionals_[next_positional++].out = arg;
  }
  for (std::size_t k = next_positional; k < positionals_.size(); ++k) {
    if (positionals_[k].required) throw ArgError("missing argument " + positionals_[k].name);
  }
  return true;
}

std::string ArgParser::help() const {
  std::ostringstream os;
  os << "usage: " << program_;
  if (!specs_.empty()) os << " [options]";
  for (const auto& p : positionals_) os << (p.required ? " " + p.name : " [" + p.name + "]");
  os << "\n\n" << summary_ << "\n";
  if (!positionals_.empty()) {
    os << "\narguments:\n";
    for (const auto& p : positionals_) os << "  " << p.name << "\n      " << p.help << "\n";
  }
  os << "\noptions:\n";
  for (const auto& s : specs_) {
    os << "  " << s.name << (s.value_name.empty() ? "" : " " + s.value_name) << "\n      " << s.help << "\n";
  }
  os << "  --help\n      show this help and exit\n";
  return os.str();
}

int run_main(const std::string& program, const std::function<int()>& body) {
  // Processes usually write into the launcher's pipes: line-buffer so lines arrive as they happen.
  std::setvbuf(stdout, nullptr, _IOLBF, 0);
  // The processes allocate and free frame-sized buffers (camera images, map messages) at every
  // frame. By default glibc hands buffers of 128 KiB and more back to the kernel (munmap, heap
  // trim) and maps them again, and every page comes back as a page fault: system time for
  // nothing (docs/runtime.md, "Memory the processes keep"). Keep them; peak RSS grows by a few MB.
  mallopt(M_MMAP_THRESHOLD, 32 << 20);  // glibc's largest
  mallopt(M_TRIM_THRESHOLD, 256 << 20);
  try {
    return body();
  } catch (const ArgError& e) {
    std::cerr << program << ": " << e.what() << "\n";
    return 2;
  } catch (const ConfigError& e) {
    std::cerr << program << ": config error: " << e.what() << "\n";
    return 2;
  } catch (const std::exception& e) {
    std::cerr << program << ": error: " << e.what() << "\n";
    return 1;
  }
}

}  // namespace semx::runtime
