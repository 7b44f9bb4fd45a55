// Textured-quad presenter: texture upload and one quad, OpenGL ES 2.
#include "drivers/display/quad_presenter.h"

#include "common/error.h"

#include <GLES2/gl2.h>
#include <opencv2/imgproc.hpp>

#include <string>

namespace avatarbooth {
namespace {

// The frame is uploaded as BGR bytes into an RGB texture (GLES 2 has no BGR format); the shader swaps back.
constexpr const char* kVertexShader = R"(#version 100
attribute vec2 position;
attribute vec2 uv;
varying vec2 v_uv;
void main() {
    v_uv = uv;
    gl_Position = vec4(position, 0.0, 1.0);
}
)";

// Texture coordinates need high precision where the GPU has it: at mediump (16-bit float) a 1920-pixel-wide
// frame would sample neighbouring texels.
constexpr const char* kFragmentShader = R"(#version 100
#ifdef GL_FRAGMENT_PRECISION_HIGH
precision highp float;
#else
precision mediump float;
#endif
varying vec2 v_uv;
uniform sampler2D frame;
void main() {
    gl_FragColor = vec4(texture2D(frame, v_uv).bgr, 1.0);
}
)";

GLuint compile(GLenum type, const char* source) {
    const GLuint shader = glCreateShader(type);
    glShaderSource(shader, 1, &source, nullptr);
    glCompileShader(shader);
    GLint ok = 0;
    glGetShaderiv(shader, GL_COMPILE_STATUS, &ok);
    if (!ok) {
        char log[1024] = {};
        glGetShaderInfoLog(shader, sizeof log, nullptr, log);
        glDeleteShader(shader);
        throw BoothError(ErrorKind::Device, "display presenter",
                         std::string(type == GL_VERTEX_SHADER ? "vertex" : "fragment") +
                             " shader does not compile: " + log);
    }
    return shader;
}

}  // namespace

QuadPresenter::QuadPresenter() {
    const GLuint vs = compile(GL_VERTEX_SHADER, kVertexShader);
    GLuint fs = 0;
    try {
        fs = compile(GL_FRAGMENT_SHADER, kFragmentShader);
    } catch (...) {
        glDeleteShader(vs);
        throw;
    }
    program_ = glCreateProgram();
    glAttachShader(program_, vs);
    glAttachShader(program_, fs);
    glLinkProgram(program_);
    glDeleteShader(vs);
    glDeleteShader(fs);
    GLint ok = 0;
    glGetProgramiv(program_, GL_LINK_STATUS, &ok);
    if (!ok) {
        char log[1024] = {};
        glGetProgramInfoLog(program_, sizeof log, nullptr, log);
        glDeleteProgram(program_);
        throw BoothError(ErrorKind::Device, "display presenter", std::string("shaders do not link: ") + log);
    }
    positionAttrib_ = glGetAttribLocation(program_, "position");
    uvAttrib_ = glGetAttribLocation(program_, "uv");
    samplerUniform_ = glGetUniformLocation(program_, "frame");
    glGenTextures(1, &texture_);
    glGenBuffers(1, &buffer_);
    glGetIntegerv(GL_MAX_TEXTURE_SIZE, &maxTextureSize_);
}

QuadPresenter::~QuadPresenter() {
    glDeleteBuffers(1, &buffer_);
    glDeleteTextures(1, &texture_);
    glDeleteProgram(program_);
}

void QuadPresenter::draw(const cv::Mat& bgr, cv::Size target, Rotation r) {
    if (bgr.empty() || bgr.type() != CV_8UC3)
        throw BoothError(ErrorKind::Internal, "display presenter", "present() needs an 8-bit BGR image");
    cv::Mat frame = bgr;
    if (maxTextureSize_ > 0 && (frame.cols > maxTextureSize_ || frame.rows > maxTextureSize_)) {
        const cv::Rect fit = fitRect(frame.size(), {maxTextureSize_, maxTextureSize_});
        cv::resize(bgr, frame, fit.size(), 0, 0, cv::INTER_AREA);
    }
    if (!frame.isContinuous()) frame = frame.clone();

    glBindTexture(GL_TEXTURE_2D, texture_);
    glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
    if (frame.size() != textureSize_) {
        // Non-power-of-two textures in GLES 2 need clamping and no mipmaps.
        glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
        glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
        glTexImage2D(GL_TEXTURE_2D, 0, GL_RGB, frame.cols, frame.rows, 0, GL_RGB, GL_UNSIGNED_BYTE, frame.data);
        textureSize_ = frame.size();
    } else {
        glTexSubImage2D(GL_TEXTURE_2D, 0, 0, 0, frame.cols, frame.rows, GL_RGB, GL_UNSIGNED_BYTE, frame.data);
    }
    const bool exact = fitRect(rotatedSize(frame.size(), r), target).size() == rotatedSize(frame.size(), r);
    const GLint filter = exact ? GL_NEAREST : GL_LINEAR;
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, filter);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, filter);

    const auto quad = panelQuad(frame.size(), target, r);
    glViewport(0, 0, target.width, target.height);
    glDisable(GL_DEPTH_TEST);
    glDisable(GL_BLEND);
    glClearColor(0, 0, 0, 1);
    glClear(GL_COLOR_BUFFER_BIT);
    glUseProgram(program_);
    glUniform1i(samplerUniform_, 0);
    glActiveTexture(GL_TEXTURE0);
    glBindBuffer(GL_ARRAY_BUFFER, buffer_);
    glBufferData(GL_ARRAY_BUFFER, sizeof quad, quad.data(), GL_STREAM_DRAW);
    const auto stride = static_cast<GLsizei>(sizeof(QuadVertex));
    glEnableVertexAttribArray(static_cast<GLuint>(positionAttrib_));
    glVertexAttribPointer(static_cast<GLuint>(positionAttrib_), 2, GL_FLOAT, GL_FALSE, stride, nullptr);
    glEnableVertexAttribArray(static_cast<GLuint>(uvAttrib_));
    glVertexAttribPointer(static_cast<GLuint>(uvAttrib_), 2, GL_FLOAT, GL_FALSE, stride,
                          reinterpret_cast<const void*>(2 * sizeof(float)));
    glDrawArrays(GL_TRIANGLE_STRIP, 0, 4);
    glDisableVertexAttribArray(static_cast<GLuint>(positionAttrib_));
    glDisableVertexAttribArray(static_cast<GLuint>(uvAttrib_));
    glBindBuffer(GL_ARRAY_BUFFER, 0);
}

}  // namespace avatarbooth
