// The lights the booth draws its avatars under (render/mesh_renderer.h), shared with the fit, which paints the
// avatar's parts so that they look under these lights as the photo showed them.
#pragma once

#include <array>

namespace avatarbooth::booth_lights {

// Directions towards the key and fill lights in eye space (x right, y up, z towards the viewer; normalised before
// use) and the light weights: colour = min(1, texture * (kAmbient + kKey max(0, n.key) + kFill max(0, n.fill))).
inline constexpr std::array<double, 3> kKeyEye{0.35, 0.55, 0.76};
inline constexpr std::array<double, 3> kFillEye{-0.70, -0.05, 0.71};
inline constexpr double kAmbient = 0.30, kKey = 0.65, kFill = 0.20;

// The light on a surface whose unit normal in eye space is n (the factor the texture is multiplied by).
double lightOn(const std::array<double, 3>& n);

// The mean light over a sphere's visible half, as the camera sees it (each image point of the sphere's disc
// counts once): about 0.75. A part that wraps round the head, as hair does, shows its painted colour at about this
// share on average.
double meanLightSeenOnSphere();

}  // namespace avatarbooth::booth_lights
