#include "monomap/exe/cli_parse.h"

#include <cstdio>

#include "monomap/exe/commands.h"
#include "monomap/util/error.h"

namespace monomap {

void ParseImageSize(const std::string& text, const std::string& option,
                    int* width, int* height) {
  int w = 0, h = 0;
  char x = 0, extra = 0;
  if (std::sscanf(text.c_str(), "%d%c%d%c", &w, &x, &h, &extra) != 3 ||
      x != 'x' || w <= 0 || h <= 0 || w > 16384 || h > 16384) {
    throw OptionsError(option + ": expected WxH like 160x120, got '" + text +
                       "'");
  }
  *width = w;
  *height = h;
}

void AddFrameRangeOptions(CLI::App* cmd, int* first_frame, int* num_frames) {
  cmd->add_option("--first-frame", *first_frame,
                  "Index of the first dataset frame to use");
  cmd->add_option("--frames", *num_frames,
                  "Number of frames to use (default: all)");
}

}  // namespace monomap
