#include "monomap/util/file.h"

#include <gtest/gtest.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <fstream>
#include <functional>
#include <iterator>

#include "monomap/util/error.h"

namespace monomap {
namespace {
namespace fs = std::filesystem;

fs::path TempDir(const std::string& name) {
  fs::path dir = fs::temp_directory_path() / ("monomap_util_test_" + name);
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

TEST(File, ReadDataLinesSkipsCommentsAndKeepsLineNumbers) {
  const fs::path dir = TempDir("lines");
  std::ofstream(dir / "a.txt") << "# header\n\n1 2\r\n  # indented\n3 4\n";
  const auto lines = ReadDataLines(dir / "a.txt");
  ASSERT_EQ(lines.size(), 2u);
  EXPECT_EQ(lines[0].number, 3);
  EXPECT_EQ(lines[0].text, "1 2");
  EXPECT_EQ(lines[1].number, 5);
}

TEST(File, MissingFileNamesThePath) {
  try {
    ReadDataLines("/nonexistent/monomap.txt");
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent/monomap.txt"),
              std::string::npos);
  }
}

TEST(File, ParseDoubleRejectsJunkAndNonFinite) {
  double v = 0;
  EXPECT_TRUE(ParseDouble("1.5e-3", &v));
  EXPECT_DOUBLE_EQ(v, 1.5e-3);
  EXPECT_FALSE(ParseDouble("1.5x", &v));
  EXPECT_FALSE(ParseDouble("nan", &v));
  EXPECT_FALSE(ParseDouble("inf", &v));
  EXPECT_FALSE(ParseDouble("", &v));
}

TEST(File, AtomicDirectoryLeavesNothingWithoutCommit) {
  const fs::path dir = TempDir("atomic");
  const fs::path out = dir / "out";
  {
    AtomicDirectory tmp(out, "test");
    std::ofstream(tmp.path() / "x.txt") << "partial";
  }
  EXPECT_FALSE(fs::exists(out));
  EXPECT_TRUE(fs::is_empty(dir));  // no temporary, no lock file
  {
    AtomicDirectory tmp(out, "test");
    std::ofstream(tmp.path() / "x.txt") << "done";
    tmp.Commit();
  }
  EXPECT_EQ(ReadFileToString(out / "x.txt"), "done");
  // Replacing an existing directory keeps only the new contents.
  {
    AtomicDirectory tmp(out, "test");
    std::ofstream(tmp.path() / "y.txt") << "new";
    tmp.Commit();
  }
  EXPECT_FALSE(fs::exists(out / "x.txt"));
  EXPECT_TRUE(fs::exists(out / "y.txt"));
  // Only the output itself is left beside it.
  EXPECT_EQ(
      std::distance(fs::directory_iterator(dir), fs::directory_iterator()), 1);
}

std::string ErrorOf(const std::function<void()>& f) {
  try {
    f();
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

TEST(File, AtomicDirectoryRefusesWhatIsNotItsOwnKind) {
  const fs::path dir = TempDir("refuse");
  std::ofstream(dir / "file") << "precious";
  fs::create_directories(dir / "foreign");
  std::ofstream(dir / "foreign" / "a.txt") << "precious";
  fs::create_directories(dir / "empty");
  {
    AtomicDirectory other(dir / "other", "dataset");
    other.Commit();
  }
  for (const char* name : {"file", "foreign", "other"}) {
    EXPECT_THROW(AtomicDirectory(dir / name, "map"), OptionsError) << name;
    EXPECT_THROW(CheckOutputDirectory(dir / name, "map", {}), OptionsError)
        << name;
  }
  EXPECT_EQ(ReadFileToString(dir / "file"), "precious");
  EXPECT_EQ(ReadFileToString(dir / "foreign" / "a.txt"), "precious");
  EXPECT_NE(ErrorOf([&] {
              CheckOutputDirectory(dir / "file", "map", {});
            }).find("is a file"),
            std::string::npos);
  EXPECT_NE(ErrorOf([&] {
              CheckOutputDirectory(dir / "other", "map", {});
            }).find("monomap dataset directory"),
            std::string::npos);
  // Absent, empty, or the same kind: accepted.
  EXPECT_NO_THROW(CheckOutputDirectory(dir / "absent", "map", {}));
  EXPECT_NO_THROW(CheckOutputDirectory(dir / "empty", "map", {}));
  EXPECT_NO_THROW(CheckOutputDirectory(dir / "other", "dataset", {}));
  {
    AtomicDirectory into_empty(dir / "empty", "map");
    into_empty.Commit();
  }
  EXPECT_TRUE(fs::exists(dir / "empty" / kOutputMarkerFile));
}

TEST(File, OutputNeverOverlapsTheInput) {
  const fs::path dir = TempDir("overlap");
  fs::create_directories(dir / "input" / "sub");
  EXPECT_THROW(CheckOutputDirectory(dir / "input", "map", {dir / "input"}),
               OptionsError);
  EXPECT_THROW(CheckOutputDirectory(dir / "input/", "map", {dir / "input"}),
               OptionsError);
  EXPECT_THROW(
      CheckOutputDirectory(dir / "input" / "map", "map", {dir / "input"}),
      OptionsError);
  EXPECT_THROW(CheckOutputDirectory(dir / "input" / ".." / "input" / "x", "map",
                                    {dir / "input"}),
               OptionsError);
  EXPECT_THROW(CheckOutputDirectory(dir, "map", {dir / "input" / "sub"}),
               OptionsError);
  EXPECT_THROW(CheckOutputFile(dir / "input" / "camera.yaml", {dir / "input"}),
               OptionsError);
  EXPECT_NO_THROW(CheckOutputDirectory(dir / "input2", "map", {dir / "input"}));
  EXPECT_THROW(CheckOutputFile(dir / "input", {}), OptionsError);
}

TEST(File, LeftoversOfInterruptedRunsAreCleanedUp) {
  const fs::path dir = TempDir("leftovers");
  {
    AtomicDirectory a(dir / "out", "map");
    std::ofstream(a.path() / "v1") << "1";
    a.Commit();
  }
  // A killed run's temporary, and an old output moved aside by a
  // two-rename commit that finished.
  fs::create_directories(dir / ".out.tmp-1234abcd");
  fs::create_directories(dir / "out.old-99ff");
  // Not ours: other names are left alone.
  fs::create_directories(dir / ".out.tmp-notours");
  fs::create_directories(dir / ".other.tmp-1234");
  {
    AtomicDirectory b(dir / "out", "map");
    EXPECT_FALSE(fs::exists(dir / ".out.tmp-1234abcd"));
    EXPECT_FALSE(fs::exists(dir / "out.old-99ff"));
    EXPECT_TRUE(fs::exists(dir / ".out.tmp-notours"));
    EXPECT_TRUE(fs::exists(dir / ".other.tmp-1234"));
  }
  EXPECT_TRUE(fs::exists(dir / "out" / "v1"));
}

TEST(File, AnOutputMovedAsideIsRestoredWhenTheTargetIsMissing) {
  const fs::path dir = TempDir("restore");
  {
    AtomicDirectory a(dir / "out", "map");
    std::ofstream(a.path() / "v1") << "1";
    a.Commit();
  }
  // A run killed between the two renames of the fallback commit.
  fs::rename(dir / "out", dir / "out.old-abc123");
  fs::create_directories(dir / ".out.tmp-def456");
  {
    AtomicDirectory b(dir / "out", "map");
    EXPECT_TRUE(fs::exists(dir / "out" / "v1"));
    EXPECT_FALSE(fs::exists(dir / "out.old-abc123"));
  }
}

TEST(File, InterruptRemovesTemporariesAndStopsCommits) {
  // In a child: the registry's interrupted state is process-wide.
  const fs::path dir = TempDir("interrupt");
  const pid_t pid = fork();
  ASSERT_GE(pid, 0);
  if (pid == 0) {
    int code = 0;
    try {
      AtomicDirectory a(dir / "out", "map");
      std::ofstream(a.path() / "x") << "partial";
      RemoveRegisteredTemporaries();
      if (fs::exists(a.path())) code = 10;
      try {
        a.Commit();
        code = 11;
      } catch (const OutputError&) {
      }
    } catch (...) {
      code = 12;
    }
    _exit(code);
  }
  int status = 0;
  ASSERT_EQ(waitpid(pid, &status, 0), pid);
  ASSERT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status), 0);
  EXPECT_TRUE(fs::is_empty(dir));
}

TEST(File, WriteFileAtomicRemovesTemporariesOfKilledRuns) {
  const fs::path dir = TempDir("file_leftovers");
  // A writer killed with SIGKILL: a child that exits at once, so its pid
  // is free (not running) afterwards.
  const pid_t dead = fork();
  ASSERT_GE(dead, 0);
  if (dead == 0) _exit(0);
  int status = 0;
  ASSERT_EQ(waitpid(dead, &status, 0), dead);
  const fs::path stale =
      dir / ("report.json.tmp-" + std::to_string(dead) + "-1a2b");
  // A writer that still runs (this process) and an unrelated file.
  const fs::path live =
      dir / ("report.json.tmp-" + std::to_string(getpid()) + "-3c4d");
  const fs::path other = dir / "report.json.tmp-notes";
  for (const fs::path& p : {stale, live, other}) std::ofstream(p) << "x";
  WriteFileAtomic(dir / "report.json", "{}\n");
  EXPECT_FALSE(fs::exists(stale));
  EXPECT_TRUE(fs::exists(live));
  EXPECT_TRUE(fs::exists(other));
  EXPECT_EQ(ReadFileToString(dir / "report.json", 100), "{}\n");
  // Nothing of its own is left behind: live, other and report.json.
  EXPECT_EQ(std::distance(fs::directory_iterator(dir), fs::directory_iterator()),
            3);
}

TEST(File, WriteFileAtomicStopsWhenInterrupted) {
  // In a child: the registry's interrupted state is process-wide.
  const fs::path dir = TempDir("file_interrupt");
  const pid_t pid = fork();
  ASSERT_GE(pid, 0);
  if (pid == 0) {
    RemoveRegisteredTemporaries();
    int code = 0;
    try {
      WriteFileAtomic(dir / "a.txt", "x");
      code = 10;
    } catch (const OutputError&) {
    }
    _exit(code);
  }
  int status = 0;
  ASSERT_EQ(waitpid(pid, &status, 0), pid);
  ASSERT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status), 0);
  EXPECT_TRUE(fs::is_empty(dir));
}

TEST(File, ReadersRefuseWhatIsNotARegularFile) {
  const fs::path dir = TempDir("special");
  ASSERT_EQ(mkfifo((dir / "fifo").c_str(), 0600), 0);
  fs::create_symlink("loop_b", dir / "loop_a");
  fs::create_symlink("loop_a", dir / "loop_b");
  fs::create_directories(dir / "d");
  // A FIFO without a writer would block a plain open forever.
  EXPECT_NE(ErrorOf([&] { ReadFileToString(dir / "fifo"); }).find("a FIFO"),
            std::string::npos);
  EXPECT_NE(ErrorOf([&] {
              ReadDataLines(dir / "loop_a");
            }).find("symbolic link loop"),
            std::string::npos);
  EXPECT_NE(ErrorOf([&] { ReadFileToString(dir / "d"); }).find("a directory"),
            std::string::npos);
  EXPECT_NE(ErrorOf([&] { ReadFileToString("/dev/zero"); }).find("a device"),
            std::string::npos);
  EXPECT_THROW(CheckRegularFile(dir / "fifo"), InputError);
  EXPECT_THROW(CheckRegularFile(dir / "loop_b"), InputError);
  std::ofstream(dir / "big") << std::string(100, 'x');
  EXPECT_NE(ErrorOf([&] {
              ReadFileToString(dir / "big", 99);
            }).find("exceeds the limit"),
            std::string::npos);
  EXPECT_EQ(ReadFileToString(dir / "big", 100).size(), 100u);
}

TEST(File, OverlongLineIsNamed) {
  const fs::path dir = TempDir("longline");
  std::ofstream(dir / "a.txt") << "1 2\n"
                               << std::string(kMaxLineBytes + 1, '7') << "\n";
  EXPECT_NE(ErrorOf([&] { ReadDataLines(dir / "a.txt"); }).find("a.txt:2:"),
            std::string::npos);
}

}  // namespace
}  // namespace monomap
