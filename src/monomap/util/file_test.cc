#include "monomap/util/file.h"

#include <gtest/gtest.h>

#include <fstream>

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
    AtomicDirectory tmp(out);
    std::ofstream(tmp.path() / "x.txt") << "partial";
  }
  EXPECT_FALSE(fs::exists(out));
  EXPECT_TRUE(fs::is_empty(dir));
  {
    AtomicDirectory tmp(out);
    std::ofstream(tmp.path() / "x.txt") << "done";
    tmp.Commit();
  }
  EXPECT_EQ(ReadFileToString(out / "x.txt"), "done");
  // Replacing an existing directory keeps only the new contents.
  {
    AtomicDirectory tmp(out);
    std::ofstream(tmp.path() / "y.txt") << "new";
    tmp.Commit();
  }
  EXPECT_FALSE(fs::exists(out / "x.txt"));
  EXPECT_TRUE(fs::exists(out / "y.txt"));
}

}  // namespace
}  // namespace monomap
