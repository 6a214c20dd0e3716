// Line-oriented text files of other codes (formats/text_lines.h).
#include "formats/text_lines.h"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdlib>

#include "formats/input_error.h"

namespace femb {

LineReader::LineReader(const std::string& path, const std::string& what) : path_(path), in_(path) {
  if (!in_) throw InputError(path + ": cannot open the " + what);
}

bool LineReader::Next(std::string* line, const std::string& comment) {
  while (std::getline(in_, *line)) {
    ++number_;
    const size_t first = line->find_first_not_of(" \t\r");
    if (first == std::string::npos) continue;
    if (!comment.empty() && line->compare(first, comment.size(), comment) == 0) continue;
    return true;
  }
  return false;
}

void LineReader::Fail(const std::string& what) const {
  throw InputError(path_ + ":" + std::to_string(number_) + ": " + what);
}

std::vector<std::string_view> Fields(const std::string& line) {
  std::vector<std::string_view> out;
  const char* p = line.data();
  const char* end = p + line.size();
  while (p < end) {
    while (p < end && (*p == ' ' || *p == '\t' || *p == ',' || *p == '\r')) ++p;
    const char* start = p;
    while (p < end && !(*p == ' ' || *p == '\t' || *p == ',' || *p == '\r')) ++p;
    if (p > start) out.emplace_back(start, size_t(p - start));
  }
  return out;
}

std::string UpperCase(std::string_view s) {
  std::string out(s);
  for (char& c : out) c = char(std::toupper(static_cast<unsigned char>(c)));
  return out;
}

std::string_view TrimBlanks(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t' || s.front() == '\r')) s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t' || s.back() == '\r')) s.remove_suffix(1);
  return s;
}

std::vector<std::string_view> CommaFields(std::string_view line) {
  std::vector<std::string_view> out;
  size_t start = 0;
  while (true) {
    const size_t comma = line.find(',', start);
    out.push_back(
        TrimBlanks(line.substr(start, comma == std::string_view::npos ? std::string_view::npos : comma - start)));
    if (comma == std::string_view::npos) break;
    start = comma + 1;
  }
  return out;
}

double NumberField(const LineReader& r, std::string_view text) {
  if (!text.empty() && text.front() == '+') text.remove_prefix(1);
  double v = 0.0;
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), v);
  if (ec != std::errc() || end != text.data() + text.size()) {
    // Fortran exponents (1.5D+03) and whatever from_chars does not take: strtod on a copy.
    std::string copy(text);
    std::replace(copy.begin(), copy.end(), 'D', 'E');
    std::replace(copy.begin(), copy.end(), 'd', 'e');
    char* stop = nullptr;
    v = std::strtod(copy.c_str(), &stop);
    if (copy.empty() || *stop != '\0') r.Fail("'" + std::string(text) + "' is not a number");
  }
  if (!std::isfinite(v)) r.Fail("entry " + std::string(text) + " is not finite");
  return v;
}

long IntegerField(const LineReader& r, std::string_view text) {
  if (!text.empty() && text.front() == '+') text.remove_prefix(1);
  long v = 0;
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), v);
  if (ec != std::errc() || end != text.data() + text.size() || text.empty()) {
    r.Fail("'" + std::string(text) + "' is not an integer");
  }
  return v;
}

}  // namespace femb
