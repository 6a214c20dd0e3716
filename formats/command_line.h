// Command lines of the femb programs: "PROGRAM INPUT [options]", options with a value or
// switches, --help, and one clear line (exit code 2) for anything else.
#pragma once

#include <functional>
#include <map>
#include <string>

namespace femb {

class CommandLine {
 public:
  /// `input_name` names the positional argument in messages ("part file", "scene file").
  CommandLine(std::string program, std::string usage, std::string input_name)
      : program_(std::move(program)), usage_(std::move(usage)), input_name_(std::move(input_name)) {}
  /// An option taking a value, under each of its spellings ("-o", "--output").
  void Value(std::initializer_list<const char*> names, std::function<void(const std::string&)> set);
  /// A switch.
  void Switch(std::initializer_list<const char*> names, std::function<void()> set);
  /// Parses; returns false when the program should exit now with exit_code() (help: 0, error: 2,
  /// after printing one line).
  bool Parse(int argc, char** argv);
  int exit_code() const { return exit_code_; }
  const std::string& input() const { return input_; }

 private:
  bool Fail(const std::string& message);
  std::string program_, usage_, input_name_, input_;
  std::map<std::string, std::function<void(const std::string&)>> values_;
  std::map<std::string, std::function<void()>> switches_;
  int exit_code_ = 0;
};

}  // namespace femb
