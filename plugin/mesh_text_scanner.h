// Shared pieces of the text mesh readers (TetGen, Gmsh, legacy VTK): a line/token scanner that
// tracks line numbers, file loading and the final orient-and-validate pass.
#pragma once

#include <cstddef>
#include <string>
#include <string_view>

#include "plugin/mesh_file_error.h"
#include "plugin/tet_mesh.h"

namespace taut::internal {

// Reads a whole file into memory; throws MeshFileError "cannot open" naming the path.
std::string ReadMeshFileText(const std::string& path);

// Quotes a token for an error message: at most 32 bytes, non-printable bytes as \xNN.
std::string QuoteToken(std::string_view token);

// Swaps nodes 0 and 1 of every tet whose signed volume det[X1-X4, X2-X4, X3-X4] / 6
// (docs/math.md §0.1) is negative, then runs ValidateTetMesh. Gmsh and VTK store tets with the
// opposite convention (det[X2-X1, X3-X1, X4-X1] > 0, which is det[X1-X4, X2-X4, X3-X4] < 0), and
// hand-made or converted files mix both, so the readers rely on no file convention and normalise
// every tet this way. Swapping two nodes is an odd permutation, so it flips the sign and keeps the
// node set. Degenerate tets are left as they are and rejected by the validation. Returns the number
// of tets that were flipped.
int OrientAndValidateTetMesh(TetMesh& mesh);

// Walks a text buffer line by line and token by token, keeping the 1-based line number so every
// error reads "file:line: reason". Lines end at '\n' (a trailing '\r' is dropped); tokens are
// separated by blanks (space, tab, CR, VT, FF); text from the comment character on is ignored.
// Numbers are parsed with std::from_chars: the whole token must be the number (a leading '+' is
// allowed), integers must fit in long long and reals must be finite. Nothing here recurses or
// allocates per token, so arbitrary bytes either scan or throw MeshFileError.
class MeshTextScanner {
 public:
  // Scans text, which is not copied and must outlive the scanner; name is used in messages.
  MeshTextScanner(std::string_view text, std::string name, char comment = '\0');

  // The file name used in messages.
  const std::string& name() const { return name_; }
  // 1-based number of the current line; 0 before the first call to NextLine.
  int line_number() const { return line_number_; }
  // The current line without its comment and line ending.
  std::string_view line() const { return line_; }
  // Bytes after the current line (an upper bound on what the rest of the file can hold).
  std::size_t bytes_left() const { return text_.size() - next_; }

  // When true, token reads continue on the following lines once the current line is used up
  // (legacy VTK); when false (default), reading past the end of a line is an error.
  void set_cross_lines(bool cross_lines) { cross_lines_ = cross_lines; }

  // Moves to the next line that holds a token; false at the end of the text.
  bool NextLine();
  // Moves to the next line, blank or not; false at the end of the text.
  bool NextRawLine();
  // NextLine, or throws "unexpected end of file while reading <what>" at the last line.
  void RequireLine(const char* what);

  // True when the current line holds no more tokens.
  bool AtLineEnd();
  // True if another token follows, on this line or (crossing lines) a later one.
  bool HasMoreTokens();
  // The next token of the current line without consuming it; empty at the end of the line.
  std::string_view PeekToken();
  // Number of tokens left on the current line.
  int CountTokensLeft() const;
  // The rest of the current line, trimmed; consumes it.
  std::string_view ReadRestOfLine();

  // Next token; throws when the line (or, crossing lines, the file) ends first.
  std::string_view ReadToken(const char* what);
  // Next token as an integer.
  long long ReadInt(const char* what);
  // Next token as an integer in [lo, hi]; throws "<what> N is out of range [lo, hi]" otherwise.
  long long ReadIntInRange(const char* what, long long lo, long long hi);
  // Next token as a finite real.
  double ReadDouble(const char* what);
  // Throws "unexpected <token> after <after>" unless the current line is used up.
  void ExpectLineEnd(const char* after);

  // A safe size to reserve for count items that each take at least min_bytes of the file: count
  // capped by what the rest of the file can hold, so a corrupt count cannot exhaust memory.
  std::size_t CapReserve(long long count, std::size_t min_bytes) const;

  // Throws MeshFileError at the current line with the streamed message.
  template <typename... Args>
  [[noreturn]] void Fail(const Args&... args) const {
    throw MeshFileError(name_, line_number_, Concat(args...));
  }

 private:
  // Skips blanks in the current line; true if a token follows.
  bool SkipBlanks();

  std::string_view text_;
  std::string name_;
  char comment_;
  bool cross_lines_ = false;
  std::size_t next_ = 0;    // offset of the first byte after the current line
  int line_number_ = 0;     // 1-based number of the current line
  std::string_view line_;   // current line, comment and line ending removed
  std::size_t cursor_ = 0;  // read position inside line_
};

}  // namespace taut::internal
