#include "monomap/util/file.h"

#include <fcntl.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <map>
#include <mutex>
#include <random>
#include <set>
#include <sstream>
#include <system_error>
#include <thread>

#include "monomap/util/error.h"

namespace monomap {
namespace fs = std::filesystem;

namespace {

// "a FIFO", "a directory", ...: what a non-regular file is, for messages.
std::string FileTypeName(mode_t mode) {
  if (S_ISDIR(mode)) return "a directory";
  if (S_ISFIFO(mode)) return "a FIFO";
  if (S_ISCHR(mode) || S_ISBLK(mode)) return "a device";
  if (S_ISSOCK(mode)) return "a socket";
  return "not a regular file";
}

std::string ErrnoText(int err) { return std::generic_category().message(err); }

[[noreturn]] void ThrowOpenError(const fs::path& path, int err) {
  if (err == ENOENT) throw InputError(path.string() + ": file not found");
  if (err == ELOOP) {
    throw InputError(path.string() + ": symbolic link loop");
  }
  throw InputError(path.string() + ": cannot open: " + ErrnoText(err));
}

// Closes a file descriptor on scope exit.
struct FdCloser {
  int fd;
  ~FdCloser() {
    if (fd >= 0) ::close(fd);
  }
};

}  // namespace

bool PathExists(const fs::path& path) {
  struct stat st {};
  return ::lstat(path.c_str(), &st) == 0;
}

void CheckRegularFile(const fs::path& path) {
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0) ThrowOpenError(path, errno);
  if (!S_ISREG(st.st_mode)) {
    throw InputError(path.string() + ": is " + FileTypeName(st.st_mode) +
                     ", expected a regular file");
  }
}

std::string ReadFileToString(const fs::path& path, int64_t max_bytes) {
  // O_NONBLOCK: opening a FIFO must not wait for a writer; the type is
  // checked on the open descriptor, so a swap after a stat cannot fool it.
  const int fd = ::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC);
  if (fd < 0) ThrowOpenError(path, errno);
  const FdCloser closer{fd};
  struct stat st {};
  if (::fstat(fd, &st) != 0) ThrowOpenError(path, errno);
  if (!S_ISREG(st.st_mode)) {
    throw InputError(path.string() + ": is " + FileTypeName(st.st_mode) +
                     ", expected a regular file");
  }
  if (st.st_size > max_bytes) {
    throw InputError(path.string() + ": file size " +
                     std::to_string(st.st_size) + " bytes exceeds the limit " +
                     std::to_string(max_bytes));
  }
  std::string contents(static_cast<size_t>(st.st_size), '\0');
  size_t done = 0;
  while (done < contents.size()) {
    const ssize_t n =
        ::read(fd, contents.data() + done, contents.size() - done);
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) {
      throw InputError(path.string() + ": read error: " + ErrnoText(errno));
    }
    if (n == 0) break;  // shrank while reading: keep what is there
    done += static_cast<size_t>(n);
  }
  contents.resize(done);
  return contents;
}

std::vector<TextLine> ReadDataLines(const fs::path& path) {
  const std::string contents = ReadFileToString(path);
  std::vector<TextLine> lines;
  int number = 0;
  size_t begin = 0;
  while (begin < contents.size()) {
    size_t end = contents.find('\n', begin);
    if (end == std::string::npos) end = contents.size();
    ++number;
    if (end - begin > kMaxLineBytes) {
      throw InputError(path.string(), number,
                       "line longer than the limit of " +
                           std::to_string(kMaxLineBytes) + " bytes");
    }
    std::string line = contents.substr(begin, end - begin);
    begin = end + 1;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    const size_t first = line.find_first_not_of(" \t");
    if (first == std::string::npos || line[first] == '#') continue;
    lines.push_back({number, std::move(line)});
  }
  return lines;
}

std::vector<std::string> SplitWhitespace(const std::string& text) {
  std::vector<std::string> tokens;
  std::istringstream in(text);
  std::string token;
  while (in >> token) tokens.push_back(token);
  return tokens;
}

bool ParseDouble(const std::string& token, double* value) {
  if (token.empty()) return false;
  char* end = nullptr;
  errno = 0;
  const double v = std::strtod(token.c_str(), &end);
  if (end != token.c_str() + token.size() || errno == ERANGE ||
      !std::isfinite(v)) {
    return false;
  }
  *value = v;
  return true;
}

namespace {

std::string RandomSuffix() {
  std::random_device rd;
  std::ostringstream s;
  s << std::hex << rd() << rd();
  return s.str();
}

bool IsHex(const std::string& text) {
  return !text.empty() &&
         std::all_of(text.begin(), text.end(),
                     [](unsigned char c) { return std::isxdigit(c) != 0; });
}

// Test hook: with MONOMAP_TEST_STOP_AT=<stage> the process stops itself
// (SIGSTOP) at that stage of a commit, so a test can look at the files at
// that exact instant and kill it there.
void TestStopPoint(const char* stage) {
  const char* want = std::getenv("MONOMAP_TEST_STOP_AT");
  if (want != nullptr && std::strcmp(want, stage) == 0) ::raise(SIGSTOP);
}

// Temporary directories of live AtomicDirectory objects, and the parent
// directory locks this process holds (one flock per parent, counted, so
// two outputs in one folder cannot deadlock the process on itself).
struct Registry {
  std::mutex mutex;
  std::set<fs::path> temporaries;
  std::map<fs::path, std::pair<int, int>> locks;  // parent -> (fd, count)
  bool interrupted = false;
};
Registry& GetRegistry() {
  static Registry* registry = new Registry;  // outlives static destructors
  return *registry;
}

int LockParent(const fs::path& parent) {
  Registry& r = GetRegistry();
  {
    std::lock_guard<std::mutex> guard(r.mutex);
    auto it = r.locks.find(parent);
    if (it != r.locks.end()) {
      ++it->second.second;
      return it->second.first;
    }
  }
  const int fd = ::open(parent.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (fd < 0) {
    throw OutputError(parent.string() + ": cannot open: " + ErrnoText(errno));
  }
  if (::flock(fd, LOCK_EX | LOCK_NB) != 0) {
    std::fprintf(stderr,
                 "monomap: waiting for another monomap run writing in %s\n",
                 parent.c_str());
    while (::flock(fd, LOCK_EX) != 0) {
      if (errno != EINTR) {
        const int err = errno;
        ::close(fd);
        throw OutputError(parent.string() + ": cannot lock: " + ErrnoText(err));
      }
    }
  }
  std::lock_guard<std::mutex> guard(r.mutex);
  r.locks[parent] = {fd, 1};
  return fd;
}

void UnlockParent(const fs::path& parent) {
  Registry& r = GetRegistry();
  std::lock_guard<std::mutex> guard(r.mutex);
  auto it = r.locks.find(parent);
  if (it == r.locks.end() || --it->second.second > 0) return;
  ::close(it->second.first);  // releases the flock
  r.locks.erase(it);
}

// The kind an output directory is marked with ("" if unmarked).
std::string OutputKind(const fs::path& dir) {
  std::error_code ec;
  if (!fs::is_regular_file(dir / kOutputMarkerFile, ec)) return "";
  try {
    std::string text = ReadFileToString(dir / kOutputMarkerFile, 4096);
    const std::string prefix = "monomap-output ";
    if (text.rfind(prefix, 0) != 0) return "";
    text = text.substr(prefix.size());
    while (!text.empty() &&
           std::isspace(static_cast<unsigned char>(text.back()))) {
      text.pop_back();
    }
    return text;
  } catch (const InputError&) {
    return "";
  }
}

// Why `path` must not be replaced by an output of `kind` ("" if it may).
std::string OutputDirectoryRefusal(const fs::path& path,
                                   const std::string& kind) {
  struct stat st {};
  if (::lstat(path.c_str(), &st) != 0) {
    if (errno == ENOENT) return "";
    return "cannot inspect it: " + ErrnoText(errno);
  }
  if (S_ISLNK(st.st_mode)) {
    return "is a symbolic link; give the directory itself";
  }
  if (!S_ISDIR(st.st_mode)) {
    return "exists and is " +
           (S_ISREG(st.st_mode) ? std::string("a file")
                                : FileTypeName(st.st_mode)) +
           "; refusing to replace it";
  }
  std::error_code ec;
  if (fs::is_empty(path, ec) && !ec) return "";
  const std::string found = OutputKind(path);
  if (found == kind) return "";
  if (found.empty()) {
    return "exists and is not a monomap " + kind + " directory (no " +
           kOutputMarkerFile +
           " marker); refusing to replace it: remove it or choose another "
           "path";
  }
  return "is a monomap " + found + " directory, not a " + kind +
         " directory; refusing to replace it";
}

// True if `a` is `b` or lies inside it (both made absolute and canonical
// as far as they exist).
bool IsSameOrInside(const fs::path& a, const fs::path& b) {
  std::error_code ec;
  const fs::path ca = fs::weakly_canonical(fs::absolute(a), ec);
  const fs::path cb = fs::weakly_canonical(fs::absolute(b), ec);
  auto ia = ca.begin();
  for (auto ib = cb.begin(); ib != cb.end(); ++ib, ++ia) {
    if (ib->empty()) continue;  // trailing separator
    if (ia == ca.end() || *ia != *ib) return false;
  }
  return true;
}

void CheckOutsideInputs(const fs::path& path,
                        const std::vector<fs::path>& inputs,
                        const std::string& option) {
  for (const fs::path& input : inputs) {
    if (input.empty()) continue;
    if (IsSameOrInside(path, input)) {
      throw OptionsError(option + " " + path.string() +
                         ": is or lies inside "
                         "the input " +
                         input.string() + "; refusing to write there");
    }
    if (IsSameOrInside(input, path)) {
      throw OptionsError(option + " " + path.string() +
                         ": contains the "
                         "input " +
                         input.string() + "; refusing to replace it");
    }
  }
}

// Removes leftovers of interrupted runs writing `name` in `parent`: the
// temporary directories, and the previous outputs a two-rename commit
// moved aside (restored instead if `name` itself is missing).
void CleanUpLeftovers(const fs::path& parent, const std::string& name) {
  const std::string tmp_prefix = "." + name + ".tmp-";
  const std::string old_prefix = name + ".old-";
  std::error_code ec;
  std::vector<fs::path> temps, olds;
  for (const auto& entry : fs::directory_iterator(parent, ec)) {
    const std::string f = entry.path().filename().string();
    if (f.rfind(tmp_prefix, 0) == 0 && IsHex(f.substr(tmp_prefix.size()))) {
      temps.push_back(entry.path());
    } else if (f.rfind(old_prefix, 0) == 0 &&
               IsHex(f.substr(old_prefix.size()))) {
      olds.push_back(entry.path());
    }
  }
  const fs::path target = parent / name;
  for (const fs::path& old : olds) {
    if (!fs::exists(fs::symlink_status(target, ec))) {
      fs::rename(old, target, ec);
      if (!ec) {
        std::fprintf(stderr, "monomap: restored %s from an interrupted run\n",
                     target.c_str());
        continue;
      }
    }
    fs::remove_all(old, ec);
  }
  for (const fs::path& temp : temps) fs::remove_all(temp, ec);
}

}  // namespace

void CheckOutputDirectory(const fs::path& path, const std::string& kind,
                          const std::vector<fs::path>& inputs,
                          const std::string& option) {
  CheckOutsideInputs(path, inputs, option);
  const std::string refusal = OutputDirectoryRefusal(path, kind);
  if (!refusal.empty()) {
    throw OptionsError(option + " " + path.string() + ": " + refusal);
  }
}

void CheckOutputFile(const fs::path& path, const std::vector<fs::path>& inputs,
                     const std::string& option) {
  CheckOutsideInputs(path, inputs, option);
  struct stat st {};
  if (::lstat(path.c_str(), &st) == 0 && !S_ISREG(st.st_mode) &&
      !S_ISLNK(st.st_mode)) {
    throw OptionsError(option + " " + path.string() + ": exists and is " +
                       FileTypeName(st.st_mode) + "; refusing to replace it");
  }
}

void MarkOutputDirectory(const fs::path& path, const std::string& kind) {
  std::error_code ec;
  fs::create_directories(path, ec);
  if (ec) {
    throw OutputError(path.string() + ": cannot create: " + ec.message());
  }
  WriteFileAtomic(path / kOutputMarkerFile, "monomap-output " + kind + "\n");
}

namespace {

// Temporary files of WriteFileAtomic are "<name>.tmp-<pid>-<hex>": the pid
// tells a leftover of a killed run from a file another run is writing.
fs::path FileTemporary(const fs::path& path) {
  return path.string() + ".tmp-" + std::to_string(::getpid()) + "-" +
         RandomSuffix();
}

// Removes the temporaries of `path` whose writer no longer runs (killed
// with SIGKILL, or the machine stopped).
void RemoveStaleFileTemporaries(const fs::path& path) {
  const fs::path parent =
      path.parent_path().empty() ? fs::path(".") : path.parent_path();
  const std::string prefix = path.filename().string() + ".tmp-";
  std::error_code ec;
  for (fs::directory_iterator it(parent, ec), end; !ec && it != end;
       it.increment(ec)) {
    const std::string name = it->path().filename().string();
    if (name.rfind(prefix, 0) != 0) continue;
    const std::string rest = name.substr(prefix.size());
    const size_t dash = rest.find('-');
    if (dash == std::string::npos || !IsHex(rest.substr(dash + 1)) ||
        rest.find_first_not_of("0123456789") != dash) {
      continue;
    }
    const pid_t pid = static_cast<pid_t>(std::stol(rest.substr(0, dash)));
    if (::kill(pid, 0) == 0 || errno != ESRCH) continue;  // still running
    std::error_code ignored;
    if (it->is_regular_file(ignored)) fs::remove(it->path(), ignored);
  }
}

}  // namespace

void WriteFileAtomic(const fs::path& path, const std::string& contents) {
  struct stat st {};
  if (::stat(path.c_str(), &st) == 0 && !S_ISREG(st.st_mode)) {
    throw OptionsError(path.string() + ": exists and is " +
                       FileTypeName(st.st_mode) + "; refusing to replace it");
  }
  RemoveStaleFileTemporaries(path);
  const fs::path temp = FileTemporary(path);
  Registry& r = GetRegistry();
  {
    // Registered so that SIGINT/SIGTERM remove it too.
    std::lock_guard<std::mutex> guard(r.mutex);
    if (r.interrupted) throw OutputError(path.string() + ": interrupted");
    r.temporaries.insert(temp);
  }
  auto unregister = [&r, &temp] {
    std::lock_guard<std::mutex> guard(r.mutex);
    r.temporaries.erase(temp);
  };
  std::error_code ec;
  {
    std::ofstream out(temp, std::ios::binary);
    out.write(contents.data(), static_cast<std::streamsize>(contents.size()));
    out.flush();
    // Named by the path the user gave: the temporary name means nothing
    // to them.
    if (!out) {
      fs::remove(temp, ec);
      unregister();
      throw OutputError(path.string() + (out.is_open() ? ": write failed"
                                                      : ": cannot open for "
                                                        "writing"));
    }
  }
  fs::rename(temp, path, ec);
  if (ec) {
    std::error_code ignored;  // keep the rename's error for the message
    fs::remove(temp, ignored);
    unregister();
    throw OutputError(path.string() + ": rename failed: " + ec.message());
  }
  unregister();
}

AtomicDirectory::AtomicDirectory(fs::path final_path, std::string kind)
    : final_path_(std::move(final_path)), kind_(std::move(kind)) {
  if (final_path_.filename().empty()) {
    final_path_ = final_path_.parent_path();
  }
  std::error_code ec;
  fs::path parent = fs::absolute(final_path_, ec).parent_path();
  fs::create_directories(parent, ec);
  if (ec) {
    throw OutputError(parent.string() + ": cannot create: " + ec.message());
  }
  // One spelling per folder: the lock registry is keyed by it.
  parent = fs::weakly_canonical(parent, ec);
  final_path_ = parent / final_path_.filename();
  lock_fd_ = LockParent(parent);
  try {
    const std::string name = final_path_.filename().string();
    CleanUpLeftovers(parent, name);
    const std::string refusal = OutputDirectoryRefusal(final_path_, kind_);
    if (!refusal.empty()) {
      throw OptionsError(final_path_.string() + ": " + refusal);
    }
    temp_path_ = parent / ("." + name + ".tmp-" + RandomSuffix());
    {
      Registry& r = GetRegistry();
      std::lock_guard<std::mutex> guard(r.mutex);
      if (r.interrupted) throw OutputError("interrupted");
      r.temporaries.insert(temp_path_);
    }
    fs::create_directory(temp_path_, ec);
    if (ec) {
      throw OutputError(temp_path_.string() +
                        ": cannot create: " + ec.message());
    }
  } catch (...) {
    if (!temp_path_.empty()) {
      Registry& r = GetRegistry();
      std::lock_guard<std::mutex> guard(r.mutex);
      r.temporaries.erase(temp_path_);
    }
    UnlockParent(parent);
    throw;
  }
}

AtomicDirectory::~AtomicDirectory() {
  std::error_code ec;
  // Before Commit: the unfinished output; after: the previous output.
  fs::remove_all(temp_path_, ec);
  {
    Registry& r = GetRegistry();
    std::lock_guard<std::mutex> guard(r.mutex);
    r.temporaries.erase(temp_path_);
  }
  UnlockParent(final_path_.parent_path());
}

void AtomicDirectory::Commit() {
  if (committed_) return;
  WriteFileAtomic(temp_path_ / kOutputMarkerFile,
                  "monomap-output " + kind_ + "\n");
  TestStopPoint("before-swap");
  Registry& r = GetRegistry();
  std::lock_guard<std::mutex> guard(r.mutex);
  if (r.interrupted) throw OutputError(final_path_.string() + ": interrupted");
  std::error_code ec;
  const bool exists = fs::exists(fs::symlink_status(final_path_, ec));
  // Swap in one step: the old output moves to the temporary name and is
  // removed by the destructor.
  if (::renameat2(AT_FDCWD, temp_path_.c_str(), AT_FDCWD, final_path_.c_str(),
                  exists ? RENAME_EXCHANGE : RENAME_NOREPLACE) == 0) {
    committed_ = true;
    TestStopPoint("after-swap");
    return;
  }
  const int err = errno;
  if (!(err == EINVAL || err == ENOSYS || err == ENOTSUP)) {
    throw OutputError(final_path_.string() +
                      ": cannot move output into "
                      "place: " +
                      ErrnoText(err));
  }
  // No RENAME_EXCHANGE on this file system: move the old output aside
  // first; the next run restores it if we die between the two renames.
  fs::path old_path;
  if (exists) {
    old_path = final_path_.string() + ".old-" + RandomSuffix();
    fs::rename(final_path_, old_path, ec);
    if (ec) {
      throw OutputError(final_path_.string() +
                        ": cannot replace: " + ec.message());
    }
  }
  TestStopPoint("between-renames");
  fs::rename(temp_path_, final_path_, ec);
  if (ec) {
    std::error_code ignored;  // keep the first error for the message
    if (!old_path.empty()) fs::rename(old_path, final_path_, ignored);
    throw OutputError(final_path_.string() + ": cannot move output into "
                      "place: " + ec.message());
  }
  committed_ = true;
  if (!old_path.empty()) fs::remove_all(old_path, ec);
}

void RemoveRegisteredTemporaries() {
  Registry& r = GetRegistry();
  std::lock_guard<std::mutex> guard(r.mutex);
  r.interrupted = true;
  for (const fs::path& temp : r.temporaries) {
    // Another thread may still be writing files into it: retry a little.
    for (int attempt = 0; attempt < 5; ++attempt) {
      std::error_code ec;
      fs::remove_all(temp, ec);
      if (!fs::exists(temp, ec)) break;
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
  }
}

}  // namespace monomap
