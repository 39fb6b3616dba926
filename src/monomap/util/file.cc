#include "monomap/util/file.h"

#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <random>
#include <sstream>
#include <system_error>

#include "monomap/util/error.h"

namespace monomap {
namespace fs = std::filesystem;

std::string ReadFileToString(const fs::path& path) {
  std::error_code ec;
  if (!fs::exists(path, ec)) {
    throw InputError(path.string() + ": file not found");
  }
  if (fs::is_directory(path, ec)) {
    throw InputError(path.string() + ": is a directory, expected a file");
  }
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path.string() + ": cannot open for reading");
  std::ostringstream out;
  out << in.rdbuf();
  if (in.bad()) throw InputError(path.string() + ": read error");
  return out.str();
}

std::vector<TextLine> ReadDataLines(const fs::path& path) {
  const std::string contents = ReadFileToString(path);
  std::vector<TextLine> lines;
  std::istringstream in(contents);
  std::string line;
  int number = 0;
  while (std::getline(in, line)) {
    ++number;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    const size_t first = line.find_first_not_of(" \t");
    if (first == std::string::npos || line[first] == '#') continue;
    lines.push_back({number, line});
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
}  // namespace

void WriteFileAtomic(const fs::path& path, const std::string& contents) {
  const fs::path temp = path.string() + ".tmp-" + RandomSuffix();
  {
    std::ofstream out(temp, std::ios::binary);
    // Named by the path the user gave: the temporary name means nothing
    // to them.
    if (!out) throw OutputError(path.string() + ": cannot open for writing");
    out.write(contents.data(), static_cast<std::streamsize>(contents.size()));
    out.flush();
    if (!out) {
      std::error_code ec;
      fs::remove(temp, ec);
      throw OutputError(path.string() + ": write failed");
    }
  }
  std::error_code ec;
  fs::rename(temp, path, ec);
  if (ec) {
    fs::remove(temp, ec);
    throw OutputError(path.string() + ": rename failed: " + ec.message());
  }
}

AtomicDirectory::AtomicDirectory(fs::path final_path)
    : final_path_(std::move(final_path)) {
  if (final_path_.filename().empty()) {
    final_path_ = final_path_.parent_path();
  }
  std::error_code ec;
  const fs::path parent = fs::absolute(final_path_, ec).parent_path();
  fs::create_directories(parent, ec);
  if (ec) {
    throw OutputError(parent.string() + ": cannot create: " + ec.message());
  }
  temp_path_ = parent / ("." + final_path_.filename().string() + ".tmp-" +
                         RandomSuffix());
  fs::create_directory(temp_path_, ec);
  if (ec) {
    throw OutputError(temp_path_.string() + ": cannot create: " +
                      ec.message());
  }
}

AtomicDirectory::~AtomicDirectory() {
  if (!committed_) {
    std::error_code ec;
    fs::remove_all(temp_path_, ec);
  }
}

void AtomicDirectory::Commit() {
  std::error_code ec;
  fs::path old_path;
  if (fs::exists(final_path_, ec)) {
    old_path = final_path_.string() + ".old-" + RandomSuffix();
    fs::rename(final_path_, old_path, ec);
    if (ec) {
      throw OutputError(final_path_.string() +
                        ": cannot replace: " + ec.message());
    }
  }
  fs::rename(temp_path_, final_path_, ec);
  if (ec) {
    if (!old_path.empty()) fs::rename(old_path, final_path_, ec);
    throw OutputError(final_path_.string() + ": cannot move output into "
                      "place: " + ec.message());
  }
  committed_ = true;
  if (!old_path.empty()) fs::remove_all(old_path, ec);
}

}  // namespace monomap
