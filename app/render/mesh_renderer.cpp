// Offscreen mesh rendering with OpenGL ES 3: multisampled FBO (colour + depth/coverage), resolved and read back.
#include "render/mesh_renderer.h"

#include "common/error.h"
#include "drivers/display/headless_egl.h"

#include <GLES3/gl3.h>
#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/type_ptr.hpp>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <limits>
#include <unordered_map>
#include <vector>

namespace avatarbooth {
namespace {

[[noreturn]] void fail(const std::string& what) {
    throw BoothError(ErrorKind::Internal, "", "mesh renderer: " + what);
}

std::string hex(unsigned value) {
    char text[16];
    std::snprintf(text, sizeof text, "0x%04X", value);
    return text;
}

// Throws when GL recorded an error since the last check; `during` says what we were doing.
void checkGl(const char* during) {
    const GLenum error = glGetError();
    if (error == GL_NO_ERROR) return;
    while (glGetError() != GL_NO_ERROR) {
    }
    fail(std::string("OpenGL error ") + hex(error) + " while " + during);
}

// Vertex: position relative to the mesh centre, welded smooth normal, texture coordinate.
struct Vertex {
    float position[3];
    float normal[3];
    float uv[2];
};

// Outward smooth normals, area-weighted, shared by all vertices at the same position (so that the copies a
// UV seam makes get one normal and the seam does not show in the shading).
std::vector<glm::dvec3> weldedNormals(const Mesh& mesh) {
    struct KeyHash {
        std::size_t operator()(const std::array<std::int64_t, 3>& k) const {
            std::size_t h = 1469598103934665603ull;
            for (const auto v : k) h = (h ^ static_cast<std::size_t>(v)) * 1099511628211ull;
            return h;
        }
    };
    constexpr double kGrid = 1e-4;  // mm: positions closer than this (after rounding) are one point
    std::unordered_map<std::array<std::int64_t, 3>, std::uint32_t, KeyHash> groupOf;
    std::vector<std::uint32_t> group(mesh.positions.size());
    for (std::size_t i = 0; i < mesh.positions.size(); ++i) {
        const glm::dvec3 q = glm::round(mesh.positions[i] / kGrid);
        const std::array<std::int64_t, 3> key{static_cast<std::int64_t>(q.x), static_cast<std::int64_t>(q.y),
                                              static_cast<std::int64_t>(q.z)};
        group[i] = groupOf.try_emplace(key, static_cast<std::uint32_t>(groupOf.size())).first->second;
    }
    std::vector<glm::dvec3> sum(groupOf.size(), glm::dvec3(0.0));
    for (const auto& t : mesh.triangles) {
        const glm::dvec3 a = mesh.positions[t.x], b = mesh.positions[t.y], c = mesh.positions[t.z];
        const glm::dvec3 n = glm::cross(b - a, c - a);  // twice the area: area weighting
        sum[group[t.x]] += n;
        sum[group[t.y]] += n;
        sum[group[t.z]] += n;
    }
    std::vector<glm::dvec3> normals(mesh.positions.size());
    for (std::size_t i = 0; i < normals.size(); ++i) {
        const double len = glm::length(sum[group[i]]);
        normals[i] = len > 0.0 ? sum[group[i]] / len : glm::dvec3(0.0, 0.0, 1.0);
    }
    return normals;
}

// The texture as tightly packed RGBA8 rows, top row first (glTF uv (0,0) = first row = GL t = 0).
cv::Mat toRgba(const cv::Mat& texture, int maxSize) {
    cv::Mat rgba;
    if (texture.empty()) {
        rgba = cv::Mat(1, 1, CV_8UC4, cv::Scalar(200, 200, 200, 255));
    } else if (texture.type() == CV_8UC3) {
        cv::cvtColor(texture, rgba, cv::COLOR_BGR2RGBA);
    } else if (texture.type() == CV_8UC4) {
        cv::cvtColor(texture, rgba, cv::COLOR_BGRA2RGBA);
    } else if (texture.type() == CV_8UC1) {
        cv::cvtColor(texture, rgba, cv::COLOR_GRAY2RGBA);
    } else {
        fail("the texture must be an 8-bit BGR, BGRA or grey image (got OpenCV type " +
             std::to_string(texture.type()) + ")");
    }
    if (rgba.cols > maxSize || rgba.rows > maxSize) {
        const double scale = static_cast<double>(maxSize) / std::max(rgba.cols, rgba.rows);
        cv::Mat smaller;
        cv::resize(rgba, smaller, cv::Size(std::clamp(static_cast<int>(rgba.cols * scale), 1, maxSize),
                                           std::clamp(static_cast<int>(rgba.rows * scale), 1, maxSize)),
                   0, 0, cv::INTER_AREA);
        rgba = smaller;
    }
    if (!rgba.isContinuous()) rgba = rgba.clone();
    return rgba;
}

constexpr const char* kVertexShader = R"(#version 300 es
layout(location = 0) in vec3 aPosition;
layout(location = 1) in vec3 aNormal;
layout(location = 2) in vec2 aUv;
uniform mat4 uMvp;
uniform mat4 uModelView;
uniform mat3 uNormalMatrix;
out vec3 vNormal;
out float vDepth;
centroid out vec2 vUv;
void main() {
    vec4 eye = uModelView * vec4(aPosition, 1.0);
    vDepth = -eye.z;
    vNormal = uNormalMatrix * aNormal;
    vUv = aUv;
    gl_Position = uMvp * vec4(aPosition, 1.0);
}
)";

constexpr const char* kFragmentShader = R"(#version 300 es
precision highp float;
uniform sampler2D uTexture;
uniform bool uLit;
uniform vec3 uKeyDir;
uniform vec3 uFillDir;
uniform vec3 uWeights;  // ambient, key, fill
uniform int uAlphaMode;  // 0 opaque, 1 mask, 2 blend (AlphaMode); 3 a masked part's fringe (under the cut-off)
uniform float uAlphaCutoff;
in vec3 vNormal;
in float vDepth;
centroid in vec2 vUv;
layout(location = 0) out vec4 oColour;
layout(location = 1) out vec4 oDepth;  // r: depth, g: coverage (resolves to the covered fraction)
void main() {
    vec4 texel = texture(uTexture, vUv);
    if (uAlphaMode == 1 && texel.a < uAlphaCutoff) discard;
    if (uAlphaMode == 3 && (texel.a >= uAlphaCutoff || texel.a < 1.0 / 255.0)) discard;
    vec3 colour = texel.rgb;
    if (uLit) {
        vec3 n = normalize(vNormal);
        if (!gl_FrontFacing) n = -n;  // inside of an open mesh: light it as its own surface
        float light = uWeights.x + uWeights.y * max(dot(n, uKeyDir), 0.0) + uWeights.z * max(dot(n, uFillDir), 0.0);
        colour = min(colour * light, vec3(1.0));
    }
    oColour = vec4(colour, uAlphaMode >= 2 ? texel.a : 1.0);
    oDepth = vec4(vDepth, 1.0, 0.0, 0.0);
}
)";

GLuint compileShader(GLenum kind, const char* source) {
    const GLuint shader = glCreateShader(kind);
    glShaderSource(shader, 1, &source, nullptr);
    glCompileShader(shader);
    GLint ok = GL_FALSE;
    glGetShaderiv(shader, GL_COMPILE_STATUS, &ok);
    if (ok != GL_TRUE) {
        std::string log(4096, '\0');
        GLsizei length = 0;
        glGetShaderInfoLog(shader, static_cast<GLsizei>(log.size()), &length, log.data());
        log.resize(static_cast<std::size_t>(length));
        glDeleteShader(shader);
        fail(std::string(kind == GL_VERTEX_SHADER ? "vertex" : "fragment") + " shader does not compile: " + log);
    }
    return shader;
}

// The largest sample count <= 4 that a renderbuffer of `format` supports (1 if none).
int maxSamples(GLenum format) {
    GLint count = 0;
    glGetInternalformativ(GL_RENDERBUFFER, format, GL_NUM_SAMPLE_COUNTS, 1, &count);
    if (count <= 0) return 1;
    std::vector<GLint> counts(static_cast<std::size_t>(count));
    glGetInternalformativ(GL_RENDERBUFFER, format, GL_SAMPLES, count, counts.data());
    int best = 1;
    for (const GLint c : counts)
        if (c <= 4) best = std::max(best, static_cast<int>(c));
    return best;
}

}  // namespace

// GL names and uniform locations; 0 = not created.
struct MeshRenderer::Gl {
    // One uploaded part: its range in the index buffer, its texture and how its alpha is used.
    struct Part {
        GLsizei firstIndex = 0, indexCount = 0;
        GLuint texture = 0;
        AlphaMode alpha = AlphaMode::Opaque;
        float alphaCutoff = 0.5f;
    };
    GLuint program = 0, vao = 0, vertexBuffer = 0, indexBuffer = 0;
    std::vector<Part> parts;  // in drawing order: opaque, masked, blended
    GLint uMvp = -1, uModelView = -1, uNormalMatrix = -1, uLit = -1, uKeyDir = -1, uFillDir = -1, uWeights = -1,
          uTexture = -1, uAlphaMode = -1, uAlphaCutoff = -1;
    GLuint msaaFbo = 0, msaaColour = 0, msaaDepthCoverage = 0, msaaDepth = 0;
    GLuint resolveFbo = 0, resolveColour = 0, resolveDepthCoverage = 0, resolveDepth = 0;
    int width = 0, height = 0;
    GLint maxRenderSize = 0;
    GLint maxTextureSize = 0;
    glm::dvec3 origin{0.0};  // the mesh centre: vertices are stored relative to it (float precision)
};

// ---- RenderCamera ----------------------------------------------------------------------------------------------

namespace {
void checkView(glm::dvec3 eye, glm::dvec3 target, glm::dvec3 up, int width, int height) {
    if (width <= 0 || height <= 0)
        fail("camera image size must be positive (got " + std::to_string(width) + "x" + std::to_string(height) + ")");
    const glm::dvec3 forward = target - eye;
    if (!(glm::length(forward) > 0.0)) fail("camera eye and target coincide");
    if (!(glm::length(glm::cross(forward, up)) > 1e-12 * glm::length(forward) * glm::length(up)))
        fail("camera up vector is zero or parallel to the view direction");
}
}  // namespace

RenderCamera RenderCamera::orthographic(glm::dvec3 eye, glm::dvec3 target, glm::dvec3 up, double mmPerPixel,
                                        int width, int height, glm::dvec2 imageCentreOffsetPx) {
    checkView(eye, target, up, width, height);
    if (!(mmPerPixel > 0.0) || !std::isfinite(mmPerPixel)) fail("orthographic camera needs mmPerPixel > 0");
    RenderCamera camera;
    camera.view = glm::lookAt(eye, target, up);
    camera.width = width;
    camera.height = height;
    // Eye space x maps to image x = W/2 + off.x + x/mpp, eye y to image y = H/2 + off.y - y/mpp.
    const double w = width, h = height;
    const double left = -(w / 2.0 + imageCentreOffsetPx.x) * mmPerPixel;
    const double right = (w / 2.0 - imageCentreOffsetPx.x) * mmPerPixel;
    const double top = (h / 2.0 + imageCentreOffsetPx.y) * mmPerPixel;
    const double bottom = -(h / 2.0 - imageCentreOffsetPx.y) * mmPerPixel;
    const double distance = glm::length(target - eye);
    camera.projection = glm::ortho(left, right, bottom, top, 0.0, 4.0 * distance + 5000.0);
    return camera;
}

RenderCamera RenderCamera::perspective(glm::dvec3 eye, glm::dvec3 target, glm::dvec3 up, double verticalFovDeg,
                                       int width, int height) {
    checkView(eye, target, up, width, height);
    if (!(verticalFovDeg > 0.0 && verticalFovDeg < 180.0)) fail("perspective camera needs 0 < fov < 180 degrees");
    RenderCamera camera;
    camera.view = glm::lookAt(eye, target, up);
    camera.width = width;
    camera.height = height;
    const double distance = glm::length(target - eye);
    camera.projection = glm::perspective(glm::radians(verticalFovDeg), static_cast<double>(width) / height,
                                         distance / 20.0, distance * 20.0);
    return camera;
}

glm::dvec2 RenderCamera::project(glm::dvec3 point) const {
    const glm::dvec4 clip = projection * view * glm::dvec4(point, 1.0);
    if (!(clip.w > 0.0)) return glm::dvec2(std::numeric_limits<double>::quiet_NaN());
    // The GL viewport transform (window x = (ndc.x + 1) W / 2, window y from the bottom), with rows counted from
    // the top as in the read-back images.
    const double ndcX = clip.x / clip.w, ndcY = clip.y / clip.w;
    return {(ndcX + 1.0) * 0.5 * width, (1.0 - ndcY) * 0.5 * height};
}

double RenderCamera::depthOf(glm::dvec3 point) const { return -(view * glm::dvec4(point, 1.0)).z; }

// ---- MeshRenderer ----------------------------------------------------------------------------------------------

MeshRenderer::MeshRenderer() : MeshRenderer(Options{}) {}

MeshRenderer::MeshRenderer(Options options) : options_(options) {
    try {
        ownedContext_ = std::make_unique<HeadlessEglContext>();
    } catch (const BoothError&) {
        throw;
    } catch (const std::exception& e) {
        fail(std::string("cannot open a GL context: ") + e.what());
    }
    context_ = ownedContext_.get();
    createPipeline();
}

MeshRenderer::MeshRenderer(HeadlessEglContext& context, Options options) : options_(options), context_(&context) {
    createPipeline();
}

MeshRenderer::~MeshRenderer() {
    try {
        makeCurrent();
        releaseAll();
    } catch (...) {
        // The context is gone or current elsewhere: its objects die with it.
    }
}

const std::string& MeshRenderer::glRenderer() const { return context_->renderer(); }

void MeshRenderer::makeCurrent() {
    try {
        context_->makeCurrent();
    } catch (const std::exception& e) {
        fail(e.what());
    }
}

void MeshRenderer::createPipeline() {
    gl_ = std::make_unique<Gl>();
    makeCurrent();
    try {
        const GLuint vs = compileShader(GL_VERTEX_SHADER, kVertexShader);
        GLuint fs = 0;
        try {
            fs = compileShader(GL_FRAGMENT_SHADER, kFragmentShader);
        } catch (...) {
            glDeleteShader(vs);
            throw;
        }
        gl_->program = glCreateProgram();
        ++liveObjects_;
        glAttachShader(gl_->program, vs);
        glAttachShader(gl_->program, fs);
        glLinkProgram(gl_->program);
        glDeleteShader(vs);  // flagged: freed with the program
        glDeleteShader(fs);
        GLint ok = GL_FALSE;
        glGetProgramiv(gl_->program, GL_LINK_STATUS, &ok);
        if (ok != GL_TRUE) {
            std::string log(4096, '\0');
            GLsizei length = 0;
            glGetProgramInfoLog(gl_->program, static_cast<GLsizei>(log.size()), &length, log.data());
            log.resize(static_cast<std::size_t>(length));
            fail("shader program does not link: " + log);
        }
        const GLuint p = gl_->program;
        gl_->uMvp = glGetUniformLocation(p, "uMvp");
        gl_->uModelView = glGetUniformLocation(p, "uModelView");
        gl_->uNormalMatrix = glGetUniformLocation(p, "uNormalMatrix");
        gl_->uLit = glGetUniformLocation(p, "uLit");
        gl_->uKeyDir = glGetUniformLocation(p, "uKeyDir");
        gl_->uFillDir = glGetUniformLocation(p, "uFillDir");
        gl_->uWeights = glGetUniformLocation(p, "uWeights");
        gl_->uTexture = glGetUniformLocation(p, "uTexture");
        gl_->uAlphaMode = glGetUniformLocation(p, "uAlphaMode");
        gl_->uAlphaCutoff = glGetUniformLocation(p, "uAlphaCutoff");

        glGenVertexArrays(1, &gl_->vao);
        glGenBuffers(1, &gl_->vertexBuffer);
        glGenBuffers(1, &gl_->indexBuffer);
        liveObjects_ += 3;
        glBindVertexArray(gl_->vao);
        glBindBuffer(GL_ARRAY_BUFFER, gl_->vertexBuffer);
        glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, gl_->indexBuffer);  // recorded in the VAO
        glEnableVertexAttribArray(0);
        glEnableVertexAttribArray(1);
        glEnableVertexAttribArray(2);
        const auto stride = static_cast<GLsizei>(sizeof(Vertex));
        const auto at = [](std::size_t offset) { return reinterpret_cast<const void*>(offset); };
        glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, stride, at(offsetof(Vertex, position)));
        glVertexAttribPointer(1, 3, GL_FLOAT, GL_FALSE, stride, at(offsetof(Vertex, normal)));
        glVertexAttribPointer(2, 2, GL_FLOAT, GL_FALSE, stride, at(offsetof(Vertex, uv)));
        glBindVertexArray(0);

        GLint maxViewport[2] = {0, 0};
        glGetIntegerv(GL_MAX_RENDERBUFFER_SIZE, &gl_->maxRenderSize);
        glGetIntegerv(GL_MAX_VIEWPORT_DIMS, maxViewport);
        gl_->maxRenderSize = std::min({gl_->maxRenderSize, maxViewport[0], maxViewport[1]});
        glGetIntegerv(GL_MAX_TEXTURE_SIZE, &gl_->maxTextureSize);
        samples_ = std::min({maxSamples(GL_RGBA8), maxSamples(GL_DEPTH_COMPONENT24), std::max(1, options_.maxSamples)});
        if (options_.depth) samples_ = std::min(samples_, maxSamples(GL_RG32F));
        checkGl("creating the shader program and vertex arrays");
    } catch (...) {
        releaseAll();
        throw;
    }
}

void MeshRenderer::destroyTargets() {
    auto dropFbo = [this](GLuint& name) {
        if (name != 0) {
            glDeleteFramebuffers(1, &name);
            --liveObjects_;
            name = 0;
        }
    };
    auto dropRenderbuffer = [this](GLuint& name) {
        if (name != 0) {
            glDeleteRenderbuffers(1, &name);
            --liveObjects_;
            name = 0;
        }
    };
    dropFbo(gl_->msaaFbo);
    dropFbo(gl_->resolveFbo);
    dropRenderbuffer(gl_->msaaColour);
    dropRenderbuffer(gl_->msaaDepthCoverage);
    dropRenderbuffer(gl_->msaaDepth);
    dropRenderbuffer(gl_->resolveColour);
    dropRenderbuffer(gl_->resolveDepthCoverage);
    dropRenderbuffer(gl_->resolveDepth);
    gl_->width = gl_->height = 0;
}

void MeshRenderer::ensureTargets(int width, int height) {
    if (gl_->width == width && gl_->height == height) return;
    destroyTargets();
    // Builds one framebuffer: colour (RGBA8), depth + coverage (RG32F), depth buffer, all with `samples`.
    auto build = [&](GLuint& fbo, GLuint& colour, GLuint& depthCoverage, GLuint& depth, int samples, bool withDepth) {
        glGenFramebuffers(1, &fbo);
        ++liveObjects_;
        glBindFramebuffer(GL_FRAMEBUFFER, fbo);
        auto attach = [&](GLuint& rb, GLenum format, GLenum attachment) {
            glGenRenderbuffers(1, &rb);
            ++liveObjects_;
            glBindRenderbuffer(GL_RENDERBUFFER, rb);
            glRenderbufferStorageMultisample(GL_RENDERBUFFER, samples > 1 ? samples : 0, format, width, height);
            glFramebufferRenderbuffer(GL_FRAMEBUFFER, attachment, GL_RENDERBUFFER, rb);
        };
        attach(colour, GL_RGBA8, GL_COLOR_ATTACHMENT0);
        if (options_.depth) attach(depthCoverage, GL_RG32F, GL_COLOR_ATTACHMENT1);
        if (withDepth) attach(depth, GL_DEPTH_COMPONENT24, GL_DEPTH_ATTACHMENT);
        const GLenum status = glCheckFramebufferStatus(GL_FRAMEBUFFER);
        if (status != GL_FRAMEBUFFER_COMPLETE)
            fail("offscreen framebuffer " + std::to_string(width) + "x" + std::to_string(height) + " with " +
                 std::to_string(samples) + " samples is incomplete (status " + hex(status) +
                 "; float colour buffers need OpenGL ES 3.2 or EXT_color_buffer_float)");
    };
    build(gl_->resolveFbo, gl_->resolveColour, gl_->resolveDepthCoverage, gl_->resolveDepth, 1, samples_ <= 1);
    if (samples_ > 1) build(gl_->msaaFbo, gl_->msaaColour, gl_->msaaDepthCoverage, gl_->msaaDepth, samples_, true);
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    glBindRenderbuffer(GL_RENDERBUFFER, 0);
    checkGl("creating the offscreen framebuffers");
    gl_->width = width;
    gl_->height = height;
}

void MeshRenderer::releaseAll() {
    if (!gl_) return;
    destroyTargets();
    auto dropBuffer = [this](GLuint& name) {
        if (name != 0) {
            glDeleteBuffers(1, &name);
            --liveObjects_;
            name = 0;
        }
    };
    dropBuffer(gl_->vertexBuffer);
    dropBuffer(gl_->indexBuffer);
    if (gl_->vao != 0) {
        glDeleteVertexArrays(1, &gl_->vao);
        --liveObjects_;
        gl_->vao = 0;
    }
    dropTextures();
    if (gl_->program != 0) {
        glDeleteProgram(gl_->program);
        --liveObjects_;
        gl_->program = 0;
    }
}

void MeshRenderer::dropTextures() {
    for (auto& part : gl_->parts)
        if (part.texture != 0) {
            glDeleteTextures(1, &part.texture);
            --liveObjects_;
        }
    gl_->parts.clear();
}

void MeshRenderer::upload(const Mesh& mesh, const cv::Mat& textureBgr) {
    AvatarPart part;
    part.mesh = mesh;
    part.texture = textureBgr;
    upload(std::vector<AvatarPart>{std::move(part)});
}

void MeshRenderer::upload(const std::vector<AvatarPart>& parts) {
    std::size_t vertexTotal = 0, triangleTotal = 0;
    for (const AvatarPart& part : parts) {
        const Mesh& mesh = part.mesh;
        const std::size_t n = mesh.positions.size();
        if (!mesh.uvs.empty() && mesh.uvs.size() != n)
            fail("the mesh has " + std::to_string(mesh.uvs.size()) + " uvs for " + std::to_string(n) + " positions");
        for (const auto& t : mesh.triangles)
            if (t.x >= n || t.y >= n || t.z >= n)
                fail("a triangle refers to vertex " + std::to_string(std::max({t.x, t.y, t.z})) + " of " +
                     std::to_string(n));
        vertexTotal += n;
        triangleTotal += mesh.triangles.size();
    }
    if (triangleTotal > static_cast<std::size_t>(std::numeric_limits<GLsizei>::max() / 3) ||
        vertexTotal > std::numeric_limits<std::uint32_t>::max())
        fail("the mesh has too many triangles");
    makeCurrent();
    const int textureLimit =
        options_.maxTextureSize > 0 ? std::min(options_.maxTextureSize, gl_->maxTextureSize) : gl_->maxTextureSize;

    // All parts in one vertex and one index buffer, relative to the centre of them all (float precision).
    glm::dvec3 lo(1e300), hi(-1e300);
    for (const AvatarPart& part : parts)
        if (!part.mesh.positions.empty()) {
            glm::dvec3 partLo, partHi;
            part.mesh.bounds(partLo, partHi);
            lo = glm::min(lo, partLo);
            hi = glm::max(hi, partHi);
        }
    gl_->origin = vertexTotal > 0 ? (lo + hi) * 0.5 : glm::dvec3(0.0);
    std::vector<Vertex> vertices;
    vertices.reserve(vertexTotal);
    std::vector<std::uint32_t> indices;
    indices.reserve(3 * triangleTotal);
    dropTextures();
    for (const AvatarPart* part : drawOrder(parts)) {
        const Mesh& mesh = part->mesh;
        const auto base = static_cast<std::uint32_t>(vertices.size());
        const std::vector<glm::dvec3> normals = weldedNormals(mesh);
        for (std::size_t i = 0; i < mesh.positions.size(); ++i) {
            const glm::vec3 p(mesh.positions[i] - gl_->origin);
            const glm::vec3 nrm(normals[i]);
            const glm::vec2 uv = mesh.uvs.empty() ? glm::vec2(0.0f) : glm::vec2(mesh.uvs[i]);
            vertices.push_back(Vertex{{p.x, p.y, p.z}, {nrm.x, nrm.y, nrm.z}, {uv.x, uv.y}});
        }
        Gl::Part drawn;
        drawn.firstIndex = static_cast<GLsizei>(indices.size());
        for (const auto& t : mesh.triangles) indices.insert(indices.end(), {base + t.x, base + t.y, base + t.z});
        drawn.indexCount = static_cast<GLsizei>(indices.size()) - drawn.firstIndex;
        drawn.alpha = part->alpha;
        drawn.alphaCutoff = static_cast<float>(part->alphaCutoff);

        const cv::Mat rgba = toRgba(part->texture, textureLimit);
        glGenTextures(1, &drawn.texture);  // storage is immutable: new textures for each upload
        ++liveObjects_;
        gl_->parts.push_back(drawn);
        glActiveTexture(GL_TEXTURE0);
        glBindTexture(GL_TEXTURE_2D, drawn.texture);
        const int levels = 1 + static_cast<int>(std::floor(std::log2(std::max(rgba.cols, rgba.rows))));
        glTexStorage2D(GL_TEXTURE_2D, levels, GL_RGBA8, rgba.cols, rgba.rows);
        glPixelStorei(GL_UNPACK_ALIGNMENT, 4);
        glPixelStorei(GL_UNPACK_ROW_LENGTH, 0);
        glPixelStorei(GL_UNPACK_SKIP_ROWS, 0);
        glPixelStorei(GL_UNPACK_SKIP_PIXELS, 0);
        glBindBuffer(GL_PIXEL_UNPACK_BUFFER, 0);
        glTexSubImage2D(GL_TEXTURE_2D, 0, 0, 0, rgba.cols, rgba.rows, GL_RGBA, GL_UNSIGNED_BYTE, rgba.data);
        glGenerateMipmap(GL_TEXTURE_2D);
        glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR_MIPMAP_LINEAR);
        glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
        glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
        glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
    }
    glBindTexture(GL_TEXTURE_2D, 0);
    glBindVertexArray(gl_->vao);
    glBindBuffer(GL_ARRAY_BUFFER, gl_->vertexBuffer);
    glBufferData(GL_ARRAY_BUFFER, static_cast<GLsizeiptr>(vertices.size() * sizeof(Vertex)), vertices.data(),
                 GL_STATIC_DRAW);
    glBufferData(GL_ELEMENT_ARRAY_BUFFER, static_cast<GLsizeiptr>(indices.size() * sizeof(std::uint32_t)),
                 indices.data(), GL_STATIC_DRAW);
    glBindVertexArray(0);
    checkGl("uploading the mesh and its texture");
    vertexCount_ = vertexTotal;
    triangleCount_ = triangleTotal;
}

void MeshRenderer::drawScene(const RenderCamera& camera, bool withDepth) {
    const int width = camera.width, height = camera.height;
    if (width <= 0 || height <= 0 || width > gl_->maxRenderSize || height > gl_->maxRenderSize)
        fail("cannot render " + std::to_string(width) + "x" + std::to_string(height) + " (limit " +
             std::to_string(gl_->maxRenderSize) + ")");
    makeCurrent();
    ensureTargets(width, height);

    // All the state we rely on, set every time (a borrowed context may have been used by others).
    const GLuint drawFbo = samples_ > 1 ? gl_->msaaFbo : gl_->resolveFbo;
    glBindFramebuffer(GL_FRAMEBUFFER, drawFbo);
    // The depth + coverage target exists only for renderers made with depth; a render that does not want it
    // (renderBgra) does not write it.
    const GLenum both[] = {GL_COLOR_ATTACHMENT0, withDepth ? static_cast<GLenum>(GL_COLOR_ATTACHMENT1) : static_cast<GLenum>(GL_NONE)};
    const GLsizei targets = options_.depth ? 2 : 1;
    glDrawBuffers(targets, both);
    glViewport(0, 0, width, height);
    glDisable(GL_SCISSOR_TEST);
    glDisable(GL_BLEND);
    glDisable(GL_CULL_FACE);
    glDisable(GL_SAMPLE_ALPHA_TO_COVERAGE);
    glDisable(GL_SAMPLE_COVERAGE);
    glDisable(GL_DITHER);
    glDisable(GL_POLYGON_OFFSET_FILL);
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_LESS);
    glDepthMask(GL_TRUE);
    glColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
    const GLfloat background[] = {static_cast<GLfloat>(camera.background[2] / 255.0),
                                  static_cast<GLfloat>(camera.background[1] / 255.0),
                                  static_cast<GLfloat>(camera.background[0] / 255.0), 0.0f};
    const GLfloat nothing[] = {0.0f, 0.0f, 0.0f, 0.0f};
    const GLfloat far = 1.0f;
    glClearBufferfv(GL_COLOR, 0, background);
    if (withDepth) glClearBufferfv(GL_COLOR, 1, nothing);
    glClearBufferfv(GL_DEPTH, 0, &far);

    if (triangleCount_ > 0) {
        const glm::dmat4 model = glm::translate(glm::dmat4(1.0), gl_->origin);
        const glm::dmat4 modelView = camera.view * model;
        const glm::mat4 mvp(camera.projection * modelView);
        const glm::mat4 mv(modelView);
        const glm::mat3 normalMatrix(glm::transpose(glm::inverse(glm::dmat3(modelView))));
        const glm::vec3 key(glm::normalize(kKeyLightEye)), fill(glm::normalize(kFillLightEye));
        glUseProgram(gl_->program);
        glUniformMatrix4fv(gl_->uMvp, 1, GL_FALSE, glm::value_ptr(mvp));
        glUniformMatrix4fv(gl_->uModelView, 1, GL_FALSE, glm::value_ptr(mv));
        glUniformMatrix3fv(gl_->uNormalMatrix, 1, GL_FALSE, glm::value_ptr(normalMatrix));
        glUniform1i(gl_->uLit, camera.lit ? 1 : 0);
        glUniform3f(gl_->uKeyDir, key.x, key.y, key.z);
        glUniform3f(gl_->uFillDir, fill.x, fill.y, fill.z);
        glUniform3f(gl_->uWeights, static_cast<float>(kAmbient), static_cast<float>(kKey), static_cast<float>(kFill));
        glUniform1i(gl_->uTexture, 0);
        glActiveTexture(GL_TEXTURE0);
        glBindVertexArray(gl_->vao);
        // Opaque and masked parts first, then the blended ones over them: blended over what is drawn, without
        // writing depth (they do not hide each other) nor the depth and coverage target (float targets do not blend).
        for (const Gl::Part& part : gl_->parts) {
            if (part.indexCount == 0) continue;
            const bool blend = part.alpha == AlphaMode::Blend;
            if (blend) {
                const GLenum colourOnly[] = {GL_COLOR_ATTACHMENT0, GL_NONE};
                glDrawBuffers(targets, colourOnly);
                glEnable(GL_BLEND);
                glBlendFuncSeparate(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA, GL_ONE, GL_ONE_MINUS_SRC_ALPHA);
                glDepthMask(GL_FALSE);
            }
            glUniform1i(gl_->uAlphaMode, static_cast<int>(part.alpha));
            glUniform1f(gl_->uAlphaCutoff, part.alphaCutoff);
            glBindTexture(GL_TEXTURE_2D, part.texture);
            glDrawElements(GL_TRIANGLES, part.indexCount, GL_UNSIGNED_INT,
                           reinterpret_cast<const void*>(static_cast<std::size_t>(part.firstIndex) * sizeof(std::uint32_t)));
        }
        // A masked part's texels under its cut-off (the soft ends of hair strands and of its hairline) blended over
        // everything drawn, in front of what is nearer than them: cut off alone, the strands' ends and the
        // hairline's edge were steps of the texture's texels. Without sorting (thousands of strand cards), where two
        // such ends overlap the nearer may be drawn first; at their opacity that does not show.
        const GLenum colourOnly[] = {GL_COLOR_ATTACHMENT0, GL_NONE};
        glDrawBuffers(targets, colourOnly);
        glEnable(GL_BLEND);
        glBlendFuncSeparate(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA, GL_ONE, GL_ONE_MINUS_SRC_ALPHA);
        glDepthMask(GL_FALSE);
        glUniform1i(gl_->uAlphaMode, 3);
        for (const Gl::Part& part : gl_->parts) {
            if (part.indexCount == 0 || part.alpha != AlphaMode::Mask) continue;
            glUniform1f(gl_->uAlphaCutoff, part.alphaCutoff);
            glBindTexture(GL_TEXTURE_2D, part.texture);
            glDrawElements(GL_TRIANGLES, part.indexCount, GL_UNSIGNED_INT,
                           reinterpret_cast<const void*>(static_cast<std::size_t>(part.firstIndex) * sizeof(std::uint32_t)));
        }
        glDisable(GL_BLEND);
        glDepthMask(GL_TRUE);
        glDrawBuffers(targets, both);
        glBindVertexArray(0);
        glBindTexture(GL_TEXTURE_2D, 0);
        glUseProgram(0);
    }

    if (samples_ > 1) {  // resolve each attachment into its single-sample twin
        glBindFramebuffer(GL_READ_FRAMEBUFFER, gl_->msaaFbo);
        glBindFramebuffer(GL_DRAW_FRAMEBUFFER, gl_->resolveFbo);
        for (int i = 0; i < (withDepth ? 2 : 1); ++i) {
            const GLenum attachment = GL_COLOR_ATTACHMENT0 + static_cast<GLenum>(i);
            const GLenum draw[] = {i == 0 ? attachment : GL_NONE, i == 1 ? attachment : GL_NONE};
            glReadBuffer(attachment);
            glDrawBuffers(targets, draw);
            glBlitFramebuffer(0, 0, width, height, 0, 0, width, height, GL_COLOR_BUFFER_BIT, GL_NEAREST);
        }
        glDrawBuffers(targets, both);
    }
}

// The resolved (single-sample) image as the read framebuffer, with the pack state glReadPixels relies on (a borrowed
// context may have changed it).
void MeshRenderer::bindResolvedForReadBack() {
    glBindFramebuffer(GL_READ_FRAMEBUFFER, gl_->resolveFbo);
    glBindBuffer(GL_PIXEL_PACK_BUFFER, 0);
    glPixelStorei(GL_PACK_ALIGNMENT, 4);
    glPixelStorei(GL_PACK_ROW_LENGTH, 0);
    glPixelStorei(GL_PACK_SKIP_ROWS, 0);
    glPixelStorei(GL_PACK_SKIP_PIXELS, 0);
}

RenderResult MeshRenderer::render(const RenderCamera& camera) {
    const int width = camera.width, height = camera.height;
    drawScene(camera, options_.depth);

    // Read back (GL rows start at the bottom) and turn into top-row-first images.
    bindResolvedForReadBack();
    cv::Mat rgba(height, width, CV_8UC4), depthCoverage;
    glReadBuffer(GL_COLOR_ATTACHMENT0);
    glReadPixels(0, 0, width, height, GL_RGBA, GL_UNSIGNED_BYTE, rgba.data);
    if (options_.depth) {
        depthCoverage.create(height, width, CV_32FC4);
        glReadBuffer(GL_COLOR_ATTACHMENT1);
        glReadPixels(0, 0, width, height, GL_RGBA, GL_FLOAT, depthCoverage.data);
    }
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    checkGl("rendering and reading back the offscreen image");

    RenderResult result;
    cv::flip(rgba, rgba, 0);
    cv::cvtColor(rgba, result.bgr, cv::COLOR_RGBA2BGR);
    cv::extractChannel(rgba, result.mask, 3);
    if (!options_.depth) return result;
    result.depth.create(height, width, CV_32F);
    for (int r = 0; r < height; ++r) {
        const auto* in = depthCoverage.ptr<cv::Vec4f>(height - 1 - r);
        auto* out = result.depth.ptr<float>(r);
        for (int c = 0; c < width; ++c) out[c] = in[c][1] > 1e-6f ? in[c][0] / in[c][1] : 0.0f;
    }
    return result;
}

void MeshRenderer::renderBgra(const RenderCamera& camera, cv::Mat& bgra) {
    const int width = camera.width, height = camera.height;
    drawScene(camera, false);
    bindResolvedForReadBack();
    readBuffer_.create(height, width, CV_8UC4);
    glReadBuffer(GL_COLOR_ATTACHMENT0);
    glReadPixels(0, 0, width, height, GL_RGBA, GL_UNSIGNED_BYTE, readBuffer_.data);
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    checkGl("rendering and reading back the offscreen image");
    // GL rows start at the bottom; alpha (cleared to 0, written 1) resolves to the covered fraction.
    bgra.create(height, width, CV_8UC4);
    cv::flip(readBuffer_, bgra, 0);
    cv::cvtColor(bgra, bgra, cv::COLOR_RGBA2BGRA);
}

}  // namespace avatarbooth
