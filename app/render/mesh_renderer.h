// Offscreen rendering of a textured head mesh, or of the avatar's parts (fit/parts/avatar_part.h), into colour,
// coverage mask and depth images (OpenGL ES 3).
#pragma once

#include "common/booth_lights.h"
#include "fit/head/mesh.h"
#include "fit/parts/avatar_part.h"

#include <glm/glm.hpp>
#include <opencv2/core.hpp>

#include <cstddef>
#include <memory>
#include <string>
#include <vector>

namespace avatarbooth {

class HeadlessEglContext;

// A view of head space: OpenGL-convention matrices (eye looks along -z, clip space -1..1) and an image size.
//
// Pixel frame used by project() and by every output image: row 0 is the top; pixel (c, r) covers
// [c, c+1) x [r, r+1), so its centre is at (c + 0.5, r + 0.5). (OpenCV's drawing and remap functions put pixel
// centres at integers: subtract 0.5 before handing project() results to them.)
struct RenderCamera {
    glm::dmat4 view{1.0};        // head space (mm) -> eye space (mm)
    glm::dmat4 projection{1.0};  // eye space -> clip space
    int width = 0;
    int height = 0;
    cv::Scalar background{0, 0, 0};  // BGR, 0..255
    bool lit = true;                 // false: output the texture colour exactly

    // An orthographic camera at `eye` looking at `target`: `target` lands on the image centre plus
    // `imageCentreOffsetPx` (x right, y down) and one pixel spans `mmPerPixel` millimetres. Clips at the eye
    // plane and beyond 4 |eye - target| + 5 m.
    static RenderCamera orthographic(glm::dvec3 eye, glm::dvec3 target, glm::dvec3 up, double mmPerPixel, int width,
                                     int height, glm::dvec2 imageCentreOffsetPx = {0.0, 0.0});
    // A perspective camera at `eye` looking at `target` (which lands on the image centre) with the given vertical
    // field of view; near and far planes at 1/20 and 20 times |eye - target|.
    static RenderCamera perspective(glm::dvec3 eye, glm::dvec3 target, glm::dvec3 up, double verticalFovDeg,
                                    int width, int height);

    // Where a head-space point lands in the image (pixel frame above), exactly as the rasteriser places it;
    // NaN for points at or behind the eye plane of a perspective camera.
    glm::dvec2 project(glm::dvec3 point) const;
    // The eye-space distance of a head-space point along the view direction (what RenderResult::depth holds).
    double depthOf(glm::dvec3 point) const;
};

struct RenderResult {
    cv::Mat bgr;    // CV_8UC3, anti-aliased against the background colour
    cv::Mat mask;   // CV_8U, 255 where the mesh covers the pixel, the covered fraction on anti-aliased edges
    cv::Mat depth;  // CV_32F, eye-space distance along the view direction in mm (mean over the covered samples),
                    // 0 where nothing
};

// What a MeshRenderer is for. The defaults suit measurement and export renders; the kiosk's avatar stage, which
// renders every frame under llvmpipe, asks for fewer samples, no depth and a smaller texture.
struct MeshRendererOptions {
    int maxSamples = 4;      // samples per pixel at most (1: no multisampling)
    bool depth = true;       // false: render() leaves RenderResult::depth empty (no depth target, no read-back)
    int maxTextureSize = 0;  // textures larger than this are scaled down on upload (0: the GL limit)
};

// Holds one mesh and its texture on the GPU and renders them into offscreen images, as often as asked.
//
// Lit renders use smooth normals welded by position (a UV seam that duplicates vertices does not show), a key light
// above-front of the camera, a soft fill from the other side and ambient light; all lights move with the camera.
// Not thread-safe: use one renderer from one thread at a time (see HeadlessEglContext::release()).
class MeshRenderer {
public:
    // The booth's lights (common/booth_lights.h): directions towards the key and fill lights in eye space and the
    // light weights, colour = min(1, texture * (kAmbient + kKey max(0, n.key) + kFill max(0, n.fill))).
    static constexpr glm::dvec3 kKeyLightEye{booth_lights::kKeyEye[0], booth_lights::kKeyEye[1], booth_lights::kKeyEye[2]};
    static constexpr glm::dvec3 kFillLightEye{booth_lights::kFillEye[0], booth_lights::kFillEye[1], booth_lights::kFillEye[2]};
    static constexpr double kAmbient = booth_lights::kAmbient, kKey = booth_lights::kKey, kFill = booth_lights::kFill;

    using Options = MeshRendererOptions;

    // Creates its own headless GL context (this costs time: create one renderer and render many views).
    MeshRenderer();
    explicit MeshRenderer(Options options);
    // Renders through a context the caller owns; it must outlive the renderer.
    explicit MeshRenderer(HeadlessEglContext& context, Options options = {});
    ~MeshRenderer();

    MeshRenderer(const MeshRenderer&) = delete;
    MeshRenderer& operator=(const MeshRenderer&) = delete;

    // Uploads a mesh and its texture (8-bit BGR, grey or BGRA, any size; empty = plain light grey), replacing any
    // previous one. Mesh uvs may be empty (the whole mesh takes the texture's top-left colour).
    void upload(const Mesh& mesh, const cv::Mat& textureBgr);
    // Uploads the avatar's parts, each with its texture, replacing what was uploaded. They are drawn opaque first,
    // then masked (fragments under the cutoff dropped), then blended over them without writing depth; RenderResult's
    // depth and coverage come from the opaque and masked parts, its colour and mask from all.
    void upload(const std::vector<AvatarPart>& parts);
    // Renders the uploaded mesh with the given camera (the background alone when nothing was uploaded).
    RenderResult render(const RenderCamera& camera);
    // The same render as one BGRA image (lit colour, coverage as alpha) written into `bgra` (reallocated only when
    // the size changes): the cheapest read-back, for a render shown on screen every frame. No depth is made.
    void renderBgra(const RenderCamera& camera, cv::Mat& bgra);

    // Vertex and triangle counts of the uploaded mesh, all parts together (0 before upload()).
    std::size_t vertexCount() const { return vertexCount_; }
    std::size_t triangleCount() const { return triangleCount_; }
    // Samples per pixel of the offscreen buffers (4 where the GPU allows, else fewer; 1 = no anti-aliasing).
    int samples() const { return samples_; }
    // The GL_RENDERER string, e.g. "llvmpipe (LLVM 15.0.6, 256 bits)".
    const std::string& glRenderer() const;
    // GL objects this renderer currently holds (program, buffers, texture, framebuffers): constant between renders.
    int liveGlObjects() const { return liveObjects_; }

private:
    struct Gl;
    void makeCurrent();
    void createPipeline();
    void destroyTargets();
    void ensureTargets(int width, int height);
    void releaseAll();
    void dropTextures();
    void bindResolvedForReadBack();
    void drawScene(const RenderCamera& camera, bool withDepth);

    Options options_;
    cv::Mat readBuffer_;  // renderBgra's GL-order read-back, kept between frames
    std::unique_ptr<HeadlessEglContext> ownedContext_;
    HeadlessEglContext* context_ = nullptr;
    std::unique_ptr<Gl> gl_;
    std::size_t vertexCount_ = 0;
    std::size_t triangleCount_ = 0;
    int samples_ = 1;
    int liveObjects_ = 0;
};

}  // namespace avatarbooth
