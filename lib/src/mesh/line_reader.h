// Line-by-line tokenizer for the text mesh formats (internal). Errors read
// "<path>:<line>: <message>".
#pragma once

#include <cstdint>
#include <fstream>
#include <string>
#include <vector>

namespace diffpd::internal {

class LineReader {
 public:
  // Opens `path`; throws what OpenInputFile (diffpd/input_file.h) throws.
  // Text from `comment` to the end of a line is dropped; '\0' means none.
  explicit LineReader(std::string path, char comment = '#');

  // Moves to the next line with at least one token; false at end of file.
  bool Next();
  const std::vector<std::string>& tokens() const { return tokens_; }
  // Whitespace-trimmed current line (comments removed).
  const std::string& line() const { return line_; }
  int line_number() const { return line_number_; }
  const std::string& path() const { return path_; }
  // Size of the file in bytes (InputFileSize).
  std::uintmax_t file_size() const { return file_size_; }

  // Throws InvalidInputError "<path>:<line>: <message>".
  [[noreturn]] void Fail(const std::string& message) const;
  // Token i as an integer / a finite double; `what` names it in the error
  // ("<path>:<line>: expected <what>, got '<token>'"), also when the line has
  // fewer than i + 1 tokens ("... got end of line").
  long ParseInt(size_t i, const std::string& what) const;
  double ParseDouble(size_t i, const std::string& what) const;
  // Token i as the number of entries the file announces: an integer in
  // [0, 2^31 - 1] and at most the file's size in bytes (each entry takes at
  // least a line), so that a corrupt count fails here instead of in an
  // allocation: "<what> must be >= 0, got -3", "<what> = 1000000000 is more
  // than the file's 120 bytes can hold".
  long ParseCount(size_t i, const std::string& what) const;
  // Fails unless the line has at least n tokens: "expected <what>".
  void RequireTokens(size_t n, const std::string& what) const;

 private:
  std::string path_;
  char comment_;
  std::ifstream stream_;
  std::uintmax_t file_size_;
  std::string line_;
  std::vector<std::string> tokens_;
  int line_number_ = 0;
};

// Parses a whole string as an integer / a finite double; false on failure.
bool ParseInt(const std::string& token, long* value);
bool ParseDouble(const std::string& token, double* value);

}  // namespace diffpd::internal
