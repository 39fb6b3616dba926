// File helpers: text reading with line numbers, atomic writes and atomic
// output directories, so a failed run never leaves half-written output.
#pragma once

#include <filesystem>
#include <functional>
#include <string>
#include <vector>

namespace monomap {

// One non-empty, non-comment line of a text file with its 1-based number.
struct TextLine {
  int number = 0;
  std::string text;
};

// Reads `path` and returns its lines that are not blank and do not start
// with '#' (after leading white space). Throws InputError if unreadable.
std::vector<TextLine> ReadDataLines(const std::filesystem::path& path);

// Reads a whole file into a string. Throws InputError if unreadable.
std::string ReadFileToString(const std::filesystem::path& path);

// Writes `contents` to `path` through a temporary file in the same folder
// and a rename, so readers see the old file or the new one, never a part.
void WriteFileAtomic(const std::filesystem::path& path,
                     const std::string& contents);

// Splits on white space.
std::vector<std::string> SplitWhitespace(const std::string& text);

// Parses a double; returns false on anything but a complete finite number.
bool ParseDouble(const std::string& token, double* value);

// An output directory that is built under a temporary name beside its
// final location and moved into place by Commit(). If the object is
// destroyed without Commit() (an exception unwound), the temporary
// directory is removed and any existing output is left untouched.
class AtomicDirectory {
 public:
  explicit AtomicDirectory(std::filesystem::path final_path);
  ~AtomicDirectory();
  AtomicDirectory(const AtomicDirectory&) = delete;
  AtomicDirectory& operator=(const AtomicDirectory&) = delete;

  // Where to write files now.
  const std::filesystem::path& path() const { return temp_path_; }
  // Replaces `final_path` (if it exists) by the finished directory.
  void Commit();

 private:
  std::filesystem::path final_path_;
  std::filesystem::path temp_path_;
  bool committed_ = false;
};

}  // namespace monomap
