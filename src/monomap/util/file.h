// File helpers: text reading with line numbers, atomic writes and atomic
// output directories, so a failed run never leaves half-written output.
#pragma once

#include <cstdint>
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

// Limits on what a file can make monomap allocate (docs/reliability.md).
// Largest input file read into memory.
inline constexpr int64_t kMaxInputFileBytes = int64_t{2} << 30;
// Longest line of a text input (rgb.txt, odometry, feature table, ...).
inline constexpr size_t kMaxLineBytes = size_t{1} << 20;

// Reads `path` and returns its lines that are not blank and do not start
// with '#' (after leading white space). Throws InputError if unreadable or
// a line is longer than kMaxLineBytes.
std::vector<TextLine> ReadDataLines(const std::filesystem::path& path);

// Reads a whole file into a string. Throws InputError naming the path if it
// is missing, not a regular file (directory, FIFO, device, symlink loop),
// larger than `max_bytes` or unreadable. Never blocks on a FIFO.
std::string ReadFileToString(const std::filesystem::path& path,
                             int64_t max_bytes = kMaxInputFileBytes);

// True if anything is at `path` (even a dangling or looping symbolic
// link, which the reader then reports). Never throws.
bool PathExists(const std::filesystem::path& path);

// Throws InputError naming the path unless it is a regular file (after
// following symbolic links). For readers that hand the path to a library.
void CheckRegularFile(const std::filesystem::path& path);

// Writes `contents` to `path` through a temporary file in the same folder
// and a rename, so readers see the old file or the new one, never a part.
// The temporary (<name>.tmp-<pid>-<hex>) is removed on SIGINT/SIGTERM
// like AtomicDirectory's; those of runs that were killed are removed by
// the next write to the same path. Throws OptionsError if `path` exists
// and is not a regular file, OutputError once interrupted.
void WriteFileAtomic(const std::filesystem::path& path,
                     const std::string& contents);

// Splits on white space.
std::vector<std::string> SplitWhitespace(const std::string& text);

// Parses a double; returns false on anything but a complete finite number.
bool ParseDouble(const std::string& token, double* value);

// Output directories carry a marker file naming their kind ("map",
// "dataset", "demo"); -o replaces only an output of the same kind.
inline constexpr char kOutputMarkerFile[] = ".monomap-output";

// Throws OptionsError (naming `option`, e.g. "-o") unless `path` is absent,
// an empty directory or a directory marked as a monomap output of `kind`,
// and unless it neither is nor contains nor lies inside one of `inputs`.
void CheckOutputDirectory(const std::filesystem::path& path,
                          const std::string& kind,
                          const std::vector<std::filesystem::path>& inputs,
                          const std::string& option = "-o");
// The same for an output file: absent or a regular file, outside `inputs`.
void CheckOutputFile(const std::filesystem::path& path,
                     const std::vector<std::filesystem::path>& inputs,
                     const std::string& option = "-o");
// Creates `path` if needed (after CheckOutputDirectory) and marks it as an
// output of `kind`. For containers filled piece by piece (demo).
void MarkOutputDirectory(const std::filesystem::path& path,
                         const std::string& kind);

// An output directory that is built under a temporary name beside its
// final location and moved into place by Commit().
// - The target keeps the old or the new directory at every instant: Commit
//   swaps them with one renameat2(RENAME_EXCHANGE) (two renames with a
//   recovery on the next run where the file system lacks it).
// - Writers in one parent directory are serialized by an flock on it, held
//   from construction to destruction; under it, leftovers of interrupted
//   runs (.NAME.tmp-*, NAME.old-*) are removed (or restored if NAME is
//   missing).
// - Temporary directories are registered so that the exe layer can remove
//   them on SIGINT/SIGTERM (RemoveRegisteredTemporaries).
// If the object is destroyed without Commit() (an exception unwound), the
// temporary directory is removed and any existing output is left untouched.
class AtomicDirectory {
 public:
  // Throws OptionsError if `final_path` exists and is not an empty
  // directory or an output of `kind`.
  AtomicDirectory(std::filesystem::path final_path, std::string kind);
  ~AtomicDirectory();
  AtomicDirectory(const AtomicDirectory&) = delete;
  AtomicDirectory& operator=(const AtomicDirectory&) = delete;

  // Where to write files now.
  const std::filesystem::path& path() const { return temp_path_; }
  // Marks the directory as an output of its kind and replaces
  // `final_path` (if it exists) by it.
  void Commit();

 private:
  std::filesystem::path final_path_;
  std::filesystem::path temp_path_;
  std::string kind_;
  int lock_fd_ = -1;
  bool committed_ = false;
};

// Removes every temporary directory of a live AtomicDirectory and makes
// later commits fail. Called by the exe layer on SIGINT/SIGTERM from a
// normal (not signal-handler) context; the process should then exit.
void RemoveRegisteredTemporaries();

}  // namespace monomap
