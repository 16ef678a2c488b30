#include "plugin/mesh_text_scanner.h"

#include <charconv>
#include <climits>
#include <cmath>
#include <fstream>
#include <iterator>
#include <sstream>
#include <utility>

namespace taut::internal {
namespace {

// Token separators inside a line.
bool IsBlank(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\v' || c == '\f'; }

// Drops a leading '+' that is followed by a digit or '.', which std::from_chars rejects.
std::string_view StripPlus(std::string_view token) {
  if (token.size() > 1 && token[0] == '+' &&
      ((token[1] >= '0' && token[1] <= '9') || token[1] == '.'))
    token.remove_prefix(1);
  return token;
}

}  // namespace

std::string ReadMeshFileText(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw MeshFileError(path, 0, "cannot open file for reading");
  std::ostringstream text;
  text << in.rdbuf();
  if (in.bad()) throw MeshFileError(path, 0, "read error");
  return std::move(text).str();
}

std::string QuoteToken(std::string_view token) {
  constexpr std::size_t kMaxBytes = 32;
  std::string out = "'";
  for (std::size_t i = 0; i < token.size() && i < kMaxBytes; ++i) {
    const unsigned char c = static_cast<unsigned char>(token[i]);
    if (c >= 0x20 && c < 0x7f && c != '\\') {
      out += static_cast<char>(c);
    } else {
      static constexpr char kHex[] = "0123456789abcdef";
      out += "\\x";
      out += kHex[c >> 4];
      out += kHex[c & 15];
    }
  }
  if (token.size() > kMaxBytes) out += "...";
  return out + "'";
}

int OrientAndValidateTetMesh(TetMesh& mesh) {
  const long long n = static_cast<long long>(mesh.nodes.size());
  int flipped = 0;
  for (auto& t : mesh.tets) {
    bool in_range = true;
    for (int a : t) in_range = in_range && a >= 0 && a < n;
    if (!in_range) continue;  // ValidateTetMesh names it below.
    const auto& X = mesh.nodes;
    if (CalcTetSignedVolume(X[t[0]], X[t[1]], X[t[2]], X[t[3]]) < 0.0) {
      std::swap(t[0], t[1]);
      ++flipped;
    }
  }
  ValidateTetMesh(mesh);
  return flipped;
}

MeshTextScanner::MeshTextScanner(std::string_view text, std::string name, char comment)
    : text_(text), name_(std::move(name)), comment_(comment) {}

bool MeshTextScanner::NextRawLine() {
  if (next_ >= text_.size()) return false;
  const std::size_t end = text_.find('\n', next_);
  const std::size_t stop = end == std::string_view::npos ? text_.size() : end;
  line_ = text_.substr(next_, stop - next_);
  next_ = end == std::string_view::npos ? text_.size() : end + 1;
  if (line_number_ < INT_MAX) ++line_number_;
  if (comment_ != '\0') {
    const std::size_t hash = line_.find(comment_);
    if (hash != std::string_view::npos) line_ = line_.substr(0, hash);
  }
  while (!line_.empty() && IsBlank(line_.back())) line_.remove_suffix(1);
  cursor_ = 0;
  return true;
}

bool MeshTextScanner::NextLine() {
  while (NextRawLine())
    if (SkipBlanks()) return true;
  return false;
}

void MeshTextScanner::RequireLine(const char* what) {
  if (!NextLine()) Fail("unexpected end of file while reading ", what);
}

bool MeshTextScanner::SkipBlanks() {
  while (cursor_ < line_.size() && IsBlank(line_[cursor_])) ++cursor_;
  return cursor_ < line_.size();
}

bool MeshTextScanner::AtLineEnd() { return !SkipBlanks(); }

bool MeshTextScanner::HasMoreTokens() {
  while (!SkipBlanks()) {
    if (!cross_lines_ || !NextLine()) return false;
  }
  return true;
}

std::string_view MeshTextScanner::PeekToken() {
  if (!SkipBlanks()) return {};
  std::size_t end = cursor_;
  while (end < line_.size() && !IsBlank(line_[end])) ++end;
  return line_.substr(cursor_, end - cursor_);
}

int MeshTextScanner::CountTokensLeft() const {
  int count = 0;
  bool in_token = false;
  for (std::size_t i = cursor_; i < line_.size(); ++i) {
    const bool blank = IsBlank(line_[i]);
    if (!blank && !in_token) ++count;
    in_token = !blank;
  }
  return count;
}

std::string_view MeshTextScanner::ReadRestOfLine() {
  SkipBlanks();
  std::string_view rest = line_.substr(cursor_);
  cursor_ = line_.size();
  return rest;
}

std::string_view MeshTextScanner::ReadToken(const char* what) {
  while (!SkipBlanks()) {
    if (!cross_lines_) Fail("expected ", what, ", found the end of the line");
    if (!NextLine()) Fail("unexpected end of file while reading ", what);
  }
  const std::size_t begin = cursor_;
  while (cursor_ < line_.size() && !IsBlank(line_[cursor_])) ++cursor_;
  return line_.substr(begin, cursor_ - begin);
}

long long MeshTextScanner::ReadInt(const char* what) {
  const std::string_view token = ReadToken(what);
  const std::string_view digits = StripPlus(token);
  long long value = 0;
  const auto [end, ec] = std::from_chars(digits.data(), digits.data() + digits.size(), value);
  if (ec == std::errc::result_out_of_range) Fail(what, " ", QuoteToken(token), " is too large");
  if (ec != std::errc() || end != digits.data() + digits.size())
    Fail("expected ", what, " (an integer), got ", QuoteToken(token));
  return value;
}

long long MeshTextScanner::ReadIntInRange(const char* what, long long lo, long long hi) {
  const long long value = ReadInt(what);
  if (value < lo || value > hi) Fail(what, " ", value, " is out of range [", lo, ", ", hi, "]");
  return value;
}

double MeshTextScanner::ReadDouble(const char* what) {
  const std::string_view token = ReadToken(what);
  const std::string_view digits = StripPlus(token);
  double value = 0.0;
  const auto [end, ec] = std::from_chars(digits.data(), digits.data() + digits.size(), value);
  if (ec == std::errc::result_out_of_range)
    Fail(what, " ", QuoteToken(token), " is out of the range of a double");
  if (ec != std::errc() || end != digits.data() + digits.size())
    Fail("expected ", what, " (a number), got ", QuoteToken(token));
  if (!std::isfinite(value)) Fail(what, " ", QuoteToken(token), " is not finite");
  return value;
}

void MeshTextScanner::ExpectLineEnd(const char* after) {
  if (SkipBlanks()) Fail("unexpected ", QuoteToken(PeekToken()), " after ", after);
}

std::size_t MeshTextScanner::CapReserve(long long count, std::size_t min_bytes) const {
  if (count <= 0) return 0;
  const std::size_t fit = bytes_left() / (min_bytes > 0 ? min_bytes : 1) + 1;
  return static_cast<unsigned long long>(count) < fit ? static_cast<std::size_t>(count) : fit;
}

}  // namespace taut::internal
