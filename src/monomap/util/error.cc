#include "monomap/util/error.h"

namespace monomap {

InputError::InputError(const std::string& file, int line,
                       const std::string& what)
    : Error(file + ":" + std::to_string(line) + ": " + what) {}

InputError::InputError(const std::string& file, const std::string& field,
                       const std::string& what)
    : Error(file + ": field '" + field + "': " + what) {}

void CheckOption(bool condition, const std::string& name,
                 const std::string& message) {
  if (!condition) throw OptionsError("option " + name + ": " + message);
}

}  // namespace monomap
