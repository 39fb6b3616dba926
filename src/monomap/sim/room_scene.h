// Moved to test_scene.h (MakeTestScene with TestLayout::kRoom, or RoomMap,
// LiveCamera, BaseFromCam, LiveImage). Kept only for the tests under
// localization/ that still include it; new code includes test_scene.h.
#pragma once

#include "monomap/sim/test_scene.h"
