// Typed exceptions thrown by the library. Only exe/ turns them into exit
// codes; library code never calls exit() or abort().
#pragma once

#include <stdexcept>
#include <string>

namespace monomap {

// Base class of every error monomap throws on purpose.
class Error : public std::runtime_error {
 public:
  explicit Error(const std::string& what) : std::runtime_error(what) {}
};

// Bad input data: a file that is missing, unreadable or malformed. The
// message names the file and, where it applies, the line or field.
class InputError : public Error {
 public:
  InputError(const std::string& file, int line, const std::string& what);
  InputError(const std::string& file, const std::string& field,
             const std::string& what);
  explicit InputError(const std::string& what) : Error(what) {}
};

// An Options struct holds a value that makes no sense.
class OptionsError : public Error {
 public:
  explicit OptionsError(const std::string& what) : Error(what) {}
};

// A stage could not produce a result from valid input (too few features,
// degenerate geometry, ...).
class StageError : public Error {
 public:
  explicit StageError(const std::string& what) : Error(what) {}
};

// Writing output failed (disk full, permission, ...).
class OutputError : public Error {
 public:
  explicit OutputError(const std::string& what) : Error(what) {}
};

// Throws OptionsError("<name>: <message>") unless `condition` holds. Used by
// the Check() method of every Options struct.
void CheckOption(bool condition, const std::string& name,
                 const std::string& message);

}  // namespace monomap
