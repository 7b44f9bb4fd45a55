// Preview images of a fitted head (front, side, three-quarter) for the reveal screen and the session folder.
#pragma once

#include "fit/head/mesh.h"
#include "render/mesh_renderer.h"

#include <opencv2/core.hpp>

#include <functional>
#include <vector>

namespace avatarbooth {

struct PreviewSet {
    cv::Mat front;         // camera on +z, looking at the face
    cv::Mat side;          // camera on -x: the subject's right side
    cv::Mat threeQuarter;  // 45 degrees between the two, slightly above
};

// How a picture is anti-aliased: by the renderer's own samples (MSAA), or, supersampled, as the mean of four renders
// shifted by a quarter pixel on a rotated grid (the four-sample MSAA pattern's places, with the texture sampled at
// each). The kiosk's background renderers draw with one sample and supersample: llvmpipe held a 512-pixel target of
// two samples at about 9 MB against 2 MB for one, while the reveal's renderers are alive beside them (README, peak RSS).
enum class Antialias { Multisample, Supersample4 };

// Lit, orthographic, square (size x size, BGR) renders of the mesh the renderer holds, each framed to the mesh's
// extent in that view with a small margin, on a neutral grey background. `mesh` must be the mesh last uploaded to
// `renderer` (with its texture); it is used for framing. Throws BoothError(Internal) when it is empty or is not
// the uploaded one.
PreviewSet renderPreviews(MeshRenderer& renderer, const Mesh& mesh, int size = 512, Antialias aa = Antialias::Multisample);

// The same of the avatar's parts (all uploaded to `renderer` with MeshRenderer::upload(parts)), framed to them all.
PreviewSet renderPreviews(MeshRenderer& renderer, const std::vector<AvatarPart>& parts, int size = 512,
                          Antialias aa = Antialias::Multisample);

// The three-quarter view alone (the same picture as PreviewSet::threeQuarter), for a second mesh such as the
// character: the same checks.
cv::Mat renderThreeQuarterPreview(MeshRenderer& renderer, const Mesh& mesh, int size = 512,
                                  Antialias aa = Antialias::Multisample);

// `frames` views of the avatar's parts (all uploaded with MeshRenderer::upload(parts)) turning once about their
// vertical axis (the first from the front, then towards the subject's left), seen from slightly above, all at one
// scale (their bounding sphere fills the square, so the head neither grows nor shrinks as it turns): lit, square
// (size x size, BGR), on the previews' grey, each handed to `each` as soon as it is drawn, none kept (the kiosk
// encodes them as they come). The same checks as renderPreviews.
void renderTurntable(MeshRenderer& renderer, const std::vector<AvatarPart>& parts, int size, int frames, Antialias aa,
                     const std::function<void(const cv::Mat&)>& each);

}  // namespace avatarbooth
