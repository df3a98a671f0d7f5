#pragma once
// Moving the camera with the mouse, as plain maths on the scene's Camera: orbit
// about the point looked at, dolly towards it, pan across the view. The viewer
// restarts the accumulation after each move (with its preview).
#include "renderer/scene/scene.h"

namespace pdflab::ui {

// Turns the eye about `lookat`: `yaw` radians about vup, `pitch` radians up or
// down (kept short of vup itself, so the view never flips over).
Camera orbit(const Camera& camera, double yaw, double pitch);
// Moves the eye towards `lookat` (factor < 1) or away (> 1); never onto it.
Camera dolly(const Camera& camera, double factor);
// Slides eye and `lookat` together across the view, by fractions of the view's
// height at the distance looked at (x right, y up).
Camera pan(const Camera& camera, double dx, double dy);
// The placement alone (size and derived vectors aside) is the same.
bool same_placement(const Camera& a, const Camera& b);

}  // namespace pdflab::ui
