#include "drapegen/renderer/depth_renderer.hpp"

#define GL_GLEXT_PROTOTYPES 1
#include <GL/osmesa.h>
#include <GL/gl.h>
#include <GL/glext.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdlib>
#include <fmt/format.h>
#include <vector>

namespace drapegen::renderer {
namespace {

constexpr const char* kVertexShader = R"(#version 330 core
layout(location = 0) in vec3 position;
uniform mat4 model_view;
uniform mat4 projection;
out vec3 eye;
void main() {
  vec4 p = model_view * vec4(position, 1.0);
  eye = p.xyz;
  gl_Position = projection * p;
}
)";

// Linear depth is the perspective-correct interpolation of the camera-space position: exact (to float rounding) on
// planar triangles. The face normal comes from the screen-space derivatives of the same position.
constexpr const char* kFragmentShader = R"(#version 330 core
in vec3 eye;
layout(location = 0) out vec2 result;
void main() {
  vec3 n = cross(dFdx(eye), dFdy(eye));
  float denominator = length(n) * length(eye);
  float c = denominator > 0.0 ? abs(dot(n, eye)) / denominator : 0.0;
  result = vec2(eye.z, min(c, 1.0));
}
)";

sim::Expected<GLuint> compile(GLenum type, const char* source) {
  const GLuint shader = glCreateShader(type);
  glShaderSource(shader, 1, &source, nullptr);
  glCompileShader(shader);
  GLint ok = 0;
  glGetShaderiv(shader, GL_COMPILE_STATUS, &ok);
  if (!ok) {
    char log[1024] = {};
    glGetShaderInfoLog(shader, sizeof log, nullptr, log);
    glDeleteShader(shader);
    return sim::Error{fmt::format("shader compilation failed: {}", log)};
  }
  return shader;
}

}  // namespace

struct DepthRenderer::Impl {
  RendererOptions options;
  OSMesaContext context = nullptr;
  std::vector<unsigned char> default_buffer = std::vector<unsigned char>(4 * 4 * 4);
  GLuint program = 0, vao = 0, vbo = 0, ebo = 0, chosen_ebo = 0, fbo = 0, color = 0, depth = 0;
  GLint model_view_location = -1, projection_location = -1;
  int fb_width = 0, fb_height = 0;
  GLsizei index_count = 0;
  std::vector<float> readback;
  TriangleMesh scene;                         // CPU copy, for skip_empty_triangles
  std::vector<Eigen::Vector2f> pixel;         // per vertex: image position (u, v) in the current view
  std::vector<unsigned char> near_clipped;    // per vertex: at or behind the near plane
  std::vector<std::array<GLuint, 3>> chosen;  // the triangles drawn in the current view

  /// Projects the scene with `P` (= K [R | t], camera pixels) and keeps in `chosen` the triangles that can cover
  /// the centre of a pixel of the W x H image; returns the pixels they can cover. A triangle covers the centre of
  /// pixel (c, r) only if (c, r) lies in its bounding box in (u, v): OpenGL samples at pixel centres, which are the
  /// integer (u, v) here (see gl_projection). The box is widened by kMargin px, far more than llvmpipe's 1/256 px
  /// vertex snapping and the float rounding between this projection and the vertex shader's, so no triangle that
  /// covers a centre is dropped. Triangles reaching the near plane are clipped by OpenGL: always kept.
  PixelBox select_triangles(const Eigen::Matrix<float, 3, 4>& P, int W, int H) {
    constexpr float kMargin = 1.0f / 64.0f;
    const float near = static_cast<float>(options.range.near) * 1.001f;
    const std::size_t nv = scene.vertices.size();
    pixel.resize(nv);
    near_clipped.resize(nv);
    for (std::size_t i = 0; i < nv; ++i) {
      const Eigen::Vector3f q = P * scene.vertices[i].homogeneous();
      near_clipped[i] = !(q.z() > near);
      pixel[i] = near_clipped[i] ? Eigen::Vector2f::Zero() : Eigen::Vector2f(q.x() / q.z(), q.y() / q.z());
    }
    chosen.clear();
    PixelBox box;
    for (const auto& t : scene.triangles) {
      const std::array<GLuint, 3> indices = {static_cast<GLuint>(t[0]), static_cast<GLuint>(t[1]),
                                             static_cast<GLuint>(t[2])};
      if (near_clipped[t[0]] || near_clipped[t[1]] || near_clipped[t[2]]) {
        chosen.push_back(indices);
        box.add(0, 0, W - 1, H - 1);
        continue;
      }
      const Eigen::Vector2f &a = pixel[t[0]], &b = pixel[t[1]], &c = pixel[t[2]];
      const Eigen::Vector2f lo = a.cwiseMin(b).cwiseMin(c), hi = a.cwiseMax(b).cwiseMax(c);
      // The pixel centres in the box, clamped to the image (in float: far-off vertices cannot overflow an int).
      const float u0 = std::max(std::ceil(lo.x() - kMargin), 0.0f);
      const float u1 = std::min(std::floor(hi.x() + kMargin), static_cast<float>(W - 1));
      const float v0 = std::max(std::ceil(lo.y() - kMargin), 0.0f);
      const float v1 = std::min(std::floor(hi.y() + kMargin), static_cast<float>(H - 1));
      if (u0 > u1 || v0 > v1) continue;
      chosen.push_back(indices);
      box.add(static_cast<int>(u0), static_cast<int>(v0), static_cast<int>(u1), static_cast<int>(v1));
    }
    return box;
  }

  bool make_current() {
    if (OSMesaGetCurrentContext() == context) return true;
    return OSMesaMakeCurrent(context, default_buffer.data(), GL_UNSIGNED_BYTE, 4, 4) == GL_TRUE;
  }

  sim::Status resize(int width, int height) {
    if (width == fb_width && height == fb_height) return {};
    if (fbo == 0) {
      glGenFramebuffers(1, &fbo);
      glGenRenderbuffers(1, &color);
      glGenRenderbuffers(1, &depth);
    }
    glBindFramebuffer(GL_FRAMEBUFFER, fbo);
    glBindRenderbuffer(GL_RENDERBUFFER, color);
    glRenderbufferStorage(GL_RENDERBUFFER, GL_RG32F, width, height);
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, color);
    glBindRenderbuffer(GL_RENDERBUFFER, depth);
    glRenderbufferStorage(GL_RENDERBUFFER, GL_DEPTH_COMPONENT32F, width, height);
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, depth);
    if (glCheckFramebufferStatus(GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE) {
      fb_width = fb_height = 0;
      return sim::Error{fmt::format("cannot make a {}x{} float framebuffer", width, height)};
    }
    fb_width = width;
    fb_height = height;
    return {};
  }

  ~Impl() {
    if (context == nullptr) return;
    if (make_current()) {
      glDeleteFramebuffers(1, &fbo);
      glDeleteRenderbuffers(1, &color);
      glDeleteRenderbuffers(1, &depth);
      glDeleteBuffers(1, &vbo);
      glDeleteBuffers(1, &ebo);
      glDeleteBuffers(1, &chosen_ebo);
      glDeleteVertexArrays(1, &vao);
      glDeleteProgram(program);
    }
    OSMesaDestroyContext(context);
  }
};

DepthRenderer::DepthRenderer(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
DepthRenderer::DepthRenderer(DepthRenderer&&) noexcept = default;
DepthRenderer& DepthRenderer::operator=(DepthRenderer&&) noexcept = default;
DepthRenderer::~DepthRenderer() = default;

sim::Expected<DepthRenderer> DepthRenderer::create(const RendererOptions& options) {
  const DepthRange& range = options.range;
  if (!(range.near > 0.0 && range.far > range.near)) return sim::Error{"renderer: need 0 < near < far"};
  if (options.threads >= 0) setenv("LP_NUM_THREADS", std::to_string(options.threads).c_str(), /*overwrite=*/0);
  auto impl = std::make_unique<Impl>();
  impl->options = options;
  const int attributes[] = {OSMESA_FORMAT, OSMESA_RGBA, OSMESA_DEPTH_BITS, 0, OSMESA_STENCIL_BITS, 0,
                            OSMESA_PROFILE, OSMESA_CORE_PROFILE, OSMESA_CONTEXT_MAJOR_VERSION, 3,
                            OSMESA_CONTEXT_MINOR_VERSION, 3, 0};
  impl->context = OSMesaCreateContextAttribs(attributes, nullptr);
  if (impl->context == nullptr) return sim::Error{"OSMesa could not create an OpenGL 3.3 core context"};
  if (!impl->make_current()) return sim::Error{"OSMesa could not make its context current"};

  auto vs = compile(GL_VERTEX_SHADER, kVertexShader);
  if (!vs) return vs.error();
  auto fs = compile(GL_FRAGMENT_SHADER, kFragmentShader);
  if (!fs) return fs.error();
  impl->program = glCreateProgram();
  glAttachShader(impl->program, *vs);
  glAttachShader(impl->program, *fs);
  glLinkProgram(impl->program);
  glDeleteShader(*vs);
  glDeleteShader(*fs);
  GLint linked = 0;
  glGetProgramiv(impl->program, GL_LINK_STATUS, &linked);
  if (!linked) return sim::Error{"shader program failed to link"};
  impl->model_view_location = glGetUniformLocation(impl->program, "model_view");
  impl->projection_location = glGetUniformLocation(impl->program, "projection");

  glGenVertexArrays(1, &impl->vao);
  glGenBuffers(1, &impl->vbo);
  glGenBuffers(1, &impl->ebo);
  glGenBuffers(1, &impl->chosen_ebo);
  glBindVertexArray(impl->vao);
  glBindBuffer(GL_ARRAY_BUFFER, impl->vbo);
  glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, impl->ebo);
  glEnableVertexAttribArray(0);
  glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, 3 * sizeof(float), nullptr);
  glEnable(GL_DEPTH_TEST);
  glDepthFunc(GL_LESS);
  glDisable(GL_CULL_FACE);  // cloth is seen from both sides
  glDisable(GL_DITHER);
  if (glGetError() != GL_NO_ERROR) return sim::Error{"OpenGL setup failed"};
  return DepthRenderer(std::move(impl));
}

sim::Status DepthRenderer::set_scene(const TriangleMesh& mesh) {
  if (sim::Status s = validate(mesh); !s) return s;
  if (!impl_->make_current()) return sim::Error{"OSMesa could not make its context current"};
  glBindVertexArray(impl_->vao);
  glBindBuffer(GL_ARRAY_BUFFER, impl_->vbo);
  glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, impl_->ebo);
  glBufferData(GL_ARRAY_BUFFER, static_cast<GLsizeiptr>(mesh.vertices.size() * 3 * sizeof(float)),
               mesh.vertices.data(), GL_STATIC_DRAW);
  glBufferData(GL_ELEMENT_ARRAY_BUFFER, static_cast<GLsizeiptr>(mesh.triangles.size() * 3 * sizeof(int)),
               mesh.triangles.data(), GL_STATIC_DRAW);
  impl_->index_count = static_cast<GLsizei>(mesh.triangles.size() * 3);
  impl_->scene = mesh;
  if (glGetError() != GL_NO_ERROR) return sim::Error{"could not upload the mesh"};
  return {};
}

sim::Expected<DepthImage> DepthRenderer::render(const Camera& camera, const Eigen::Isometry3d& model) {
  if (sim::Status s = check_view(camera, model); !s) return s.error();
  const int W = camera.intrinsics.width, H = camera.intrinsics.height;
  if (impl_->index_count == 0) return sim::Error{"no scene to render (call set_scene first)"};
  if (!impl_->make_current()) return sim::Error{"OSMesa could not make its context current"};
  if (sim::Status s = impl_->resize(W, H); !s) return s.error();

  const Eigen::Matrix4f model_view = (camera.world_to_camera * model).matrix().cast<float>();
  const DepthRange& range = impl_->options.range;
  const Eigen::Matrix4f projection = gl_projection(camera.intrinsics, range.near, range.far).cast<float>();
  glBindFramebuffer(GL_FRAMEBUFFER, impl_->fbo);
  glViewport(0, 0, W, H);
  glClearColor(0.0f, 0.0f, 0.0f, 0.0f);
  glClearDepth(1.0);
  glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
  glUseProgram(impl_->program);
  glUniformMatrix4fv(impl_->model_view_location, 1, GL_FALSE, model_view.data());  // Eigen is column-major
  glUniformMatrix4fv(impl_->projection_location, 1, GL_FALSE, projection.data());
  glBindVertexArray(impl_->vao);
  // The pixels that can have a return; the rest of the image stays background (0) and is not read back.
  PixelBox box{0, 0, W - 1, H - 1};
  if (impl_->options.skip_empty_triangles) {
    const Eigen::Matrix<float, 3, 4> P = camera.intrinsics.K.cast<float>() * model_view.topRows<3>();
    box = impl_->select_triangles(P, W, H);
    const auto& chosen = impl_->chosen;
    glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, impl_->chosen_ebo);  // recorded in the VAO
    glBufferData(GL_ELEMENT_ARRAY_BUFFER, static_cast<GLsizeiptr>(chosen.size() * sizeof(chosen[0])), chosen.data(),
                 GL_STREAM_DRAW);
    if (!chosen.empty())
      glDrawElements(GL_TRIANGLES, static_cast<GLsizei>(3 * chosen.size()), GL_UNSIGNED_INT, nullptr);
  } else {
    glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, impl_->ebo);
    glDrawElements(GL_TRIANGLES, impl_->index_count, GL_UNSIGNED_INT, nullptr);
  }

  DepthImage image(W, H);
  image.incidence.resize(image.depth.size());
  if (!box.empty()) {
    const int w = box.u1 - box.u0 + 1, h = box.v1 - box.v0 + 1;
    auto& buffer = impl_->readback;
    buffer.resize(static_cast<std::size_t>(2) * w * h);
    glPixelStorei(GL_PACK_ALIGNMENT, 4);
    glReadPixels(box.u0, box.v0, w, h, GL_RG, GL_FLOAT, buffer.data());
    for (int r = 0; r < h; ++r) {
      const float* in = buffer.data() + static_cast<std::size_t>(2) * w * r;
      const std::size_t out = static_cast<std::size_t>(box.v0 + r) * W + box.u0;
      for (int c = 0; c < w; ++c) {
        image.depth[out + c] = in[2 * c];
        image.incidence[out + c] = in[2 * c + 1];
      }
    }
  }
  if (const GLenum e = glGetError(); e != GL_NO_ERROR) return sim::Error{fmt::format("OpenGL error 0x{:x}", e)};
  return image;
}

std::string DepthRenderer::name() const {
  if (!impl_->make_current()) return "unknown";
  const auto* name = reinterpret_cast<const char*>(glGetString(GL_RENDERER));
  return name != nullptr ? name : "unknown";
}

}  // namespace drapegen::renderer
