// Moved to test_scene.h (MakeTestScene with TestLayout::kDesk, or LookAt,
// ProceduralTexture, RayCaster, HorizontalRectangle, MakePlaneFeatures).
// Kept only until its last includer moves; new code includes test_scene.h.
#pragma once

#include "monomap/sim/test_scene.h"
