// Line-oriented text files of other codes (FE matrices, Abaqus decks): lines with their numbers,
// fields split without copies, and numbers parsed with the file and line named on failure.
#pragma once

#include <fstream>
#include <string>
#include <string_view>
#include <vector>

namespace femb {

/// Lines of a text file with their 1-based numbers; blank lines and lines starting with
/// `comment` (after leading blanks) skipped.
class LineReader {
 public:
  /// Throws InputError "PATH: cannot open the WHAT".
  LineReader(const std::string& path, const std::string& what);
  /// The next line that is neither blank nor a comment; false at the end of the file.
  bool Next(std::string* line, const std::string& comment);
  /// Throws InputError "PATH:LINE: WHAT" for the line read last.
  [[noreturn]] void Fail(const std::string& what) const;
  long number() const { return number_; }
  const std::string& path() const { return path_; }

 private:
  std::string path_;
  std::ifstream in_;
  long number_ = 0;
};

/// Whitespace- or comma-separated fields, as views into `line` (no copies: a million-entry matrix
/// file is parsed in about a second).
std::vector<std::string_view> Fields(const std::string& line);

/// Comma-separated fields with surrounding blanks trimmed; empty fields kept ("1, , 2" gives
/// three). Abaqus data lines.
std::vector<std::string_view> CommaFields(std::string_view line);

/// `s` in upper case (ASCII).
std::string UpperCase(std::string_view s);

/// `s` without leading and trailing blanks, tabs and carriage returns.
std::string_view TrimBlanks(std::string_view s);

/// A finite number (a leading '+' and Fortran exponents 1.5D+03 allowed); otherwise r.Fail.
double NumberField(const LineReader& r, std::string_view text);

/// An integer; otherwise r.Fail.
long IntegerField(const LineReader& r, std::string_view text);

}  // namespace femb
