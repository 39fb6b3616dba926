// Parsing of option values shared by the subcommands.
#pragma once

#include <string>

namespace monomap {

// "WxH" (e.g. "160x120", both in [1, 16384]) -> *width, *height. Throws
// OptionsError naming `option` otherwise.
void ParseImageSize(const std::string& text, const std::string& option,
                    int* width, int* height);

}  // namespace monomap
