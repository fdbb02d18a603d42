#include "mesh/line_reader.h"

#include <charconv>
#include <cmath>
#include <limits>
#include <sstream>

#include "diffpd/error.h"
#include "diffpd/input_file.h"

namespace diffpd::internal {

bool ParseInt(const std::string& token, long* value) {
  const char* begin = token.data();
  const char* end = begin + token.size();
  if (begin != end && *begin == '+') ++begin;
  const auto result = std::from_chars(begin, end, *value);
  return result.ec == std::errc() && result.ptr == end && begin != end;
}

bool ParseDouble(const std::string& token, double* value) {
  const char* begin = token.data();
  const char* end = begin + token.size();
  if (begin != end && *begin == '+') ++begin;
  const auto result = std::from_chars(begin, end, *value);
  return result.ec == std::errc() && result.ptr == end && begin != end && std::isfinite(*value);
}

LineReader::LineReader(std::string path, char comment)
    : path_(std::move(path)), comment_(comment), stream_(OpenInputFile(path_)), file_size_(InputFileSize(path_)) {}

bool LineReader::Next() {
  while (std::getline(stream_, line_)) {
    ++line_number_;
    if (comment_ != '\0') {
      const size_t pos = line_.find(comment_);
      if (pos != std::string::npos) line_.erase(pos);
    }
    // The blanks are those operator>> skips (std::isspace), so that a line
    // left with text has at least one token.
    const char* const blanks = " \t\r\n\f\v";
    const size_t first = line_.find_first_not_of(blanks);
    if (first == std::string::npos) continue;
    line_ = line_.substr(first, line_.find_last_not_of(blanks) - first + 1);
    tokens_.clear();
    std::istringstream split(line_);
    for (std::string token; split >> token;) tokens_.push_back(token);
    if (!tokens_.empty()) return true;
  }
  tokens_.clear();
  line_.clear();
  return false;
}

void LineReader::Fail(const std::string& message) const {
  throw InvalidInputError(path_ + ":" + std::to_string(line_number_) + ": " + message);
}

void LineReader::RequireTokens(size_t n, const std::string& what) const {
  if (tokens_.size() < n) Fail("expected " + what + ", got '" + line_ + "'");
}

long LineReader::ParseInt(size_t i, const std::string& what) const {
  long value = 0;
  if (i >= tokens_.size()) Fail("expected " + what + ", got end of line");
  if (!internal::ParseInt(tokens_[i], &value)) Fail("expected " + what + ", got '" + tokens_[i] + "'");
  return value;
}

long LineReader::ParseCount(size_t i, const std::string& what) const {
  const long count = ParseInt(i, what);
  if (count < 0) Fail(what + " must be >= 0, got " + tokens_[i]);
  if (static_cast<std::uintmax_t>(count) > file_size_)
    Fail(what + " = " + tokens_[i] + " is more than the file's " + std::to_string(file_size_) + " bytes can hold");
  if (count > std::numeric_limits<int>::max())
    Fail(what + " = " + tokens_[i] + " is too large (at most " + std::to_string(std::numeric_limits<int>::max()) + ")");
  return count;
}

double LineReader::ParseDouble(size_t i, const std::string& what) const {
  double value = 0;
  if (i >= tokens_.size()) Fail("expected " + what + ", got end of line");
  if (!internal::ParseDouble(tokens_[i], &value)) {
    Fail("expected " + what + " (a finite number), got '" + tokens_[i] + "'");
  }
  return value;
}

}  // namespace diffpd::internal
