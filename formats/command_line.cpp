#include "formats/command_line.h"

#include <cstdio>

namespace femb {

void CommandLine::Value(std::initializer_list<const char*> names, std::function<void(const std::string&)> set) {
  for (const char* n : names) values_[n] = set;
}

void CommandLine::Switch(std::initializer_list<const char*> names, std::function<void()> set) {
  for (const char* n : names) switches_[n] = set;
}

bool CommandLine::Fail(const std::string& message) {
  std::fprintf(stderr, "%s: %s\n", program_.c_str(), message.c_str());
  exit_code_ = 2;
  return false;
}

bool CommandLine::Parse(int argc, char** argv) {
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "-h" || a == "--help") {
      std::fputs(usage_.c_str(), stdout);
      exit_code_ = 0;
      return false;
    }
    if (auto v = values_.find(a); v != values_.end()) {
      if (i + 1 >= argc) return Fail(a + " needs a value (see --help)");
      v->second(argv[++i]);
    } else if (auto s = switches_.find(a); s != switches_.end()) {
      s->second();
    } else if (!a.empty() && a[0] == '-') {
      return Fail("unknown option '" + a + "' (see --help)");
    } else if (input_.empty()) {
      input_ = a;
    } else {
      return Fail("more than one " + input_name_ + " given ('" + input_ + "', '" + a + "')");
    }
  }
  if (input_.empty()) {
    std::fprintf(stderr, "%s: no %s given\n%s", program_.c_str(), input_name_.c_str(), usage_.c_str());
    exit_code_ = 2;
    return false;
  }
  return true;
}

}  // namespace femb
