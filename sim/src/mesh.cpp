// Triangle meshes: primitives, the deformable sheet, files through Assimp.
#include "ofv/sim/mesh.h"
#include "ofv/constants.h"

#include <assimp/cimport.h>
#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include <cmath>
#include <functional>
#include <stdexcept>

namespace ofv::sim {

namespace {


// Flips triangles whose normal points towards `inside(centroid)`, the nearest
// interior point of a convex shape, so that every normal points outwards.
void orient_outward(TriangleMesh& m,
                    const std::function<Eigen::Vector3f(const Eigen::Vector3f&)>& inside) {
  for (auto& t : m.triangles) {
    const Eigen::Vector3f a = m.vertices[t[0]], b = m.vertices[t[1]], c = m.vertices[t[2]];
    const Eigen::Vector3f centroid = (a + b + c) / 3.0f;
    if ((b - a).cross(c - a).dot(centroid - inside(centroid)) < 0.0f) std::swap(t[1], t[2]);
  }
}

// Rings of vertices around z at the given (z, radius) profile, closed by poles.
TriangleMesh revolve(const std::vector<std::pair<double, double>>& profile, int slices) {
  TriangleMesh m;
  const int n = static_cast<int>(profile.size());
  m.vertices.emplace_back(0.0f, 0.0f, static_cast<float>(profile.front().first));  // bottom pole
  for (int r = 1; r + 1 < n; ++r) {
    for (int s = 0; s < slices; ++s) {
      const double a = 2.0 * kPi * s / slices;
      m.vertices.emplace_back(static_cast<float>(profile[r].second * std::cos(a)),
                              static_cast<float>(profile[r].second * std::sin(a)),
                              static_cast<float>(profile[r].first));
    }
  }
  m.vertices.emplace_back(0.0f, 0.0f, static_cast<float>(profile.back().first));  // top pole
  const int top = static_cast<int>(m.vertices.size()) - 1;
  auto ring = [&](int r, int s) { return 1 + (r - 1) * slices + (s % slices); };
  for (int s = 0; s < slices; ++s) {
    m.triangles.emplace_back(0, ring(1, s + 1), ring(1, s));
    m.triangles.emplace_back(top, ring(n - 2, s), ring(n - 2, s + 1));
  }
  for (int r = 1; r + 2 < n; ++r) {
    for (int s = 0; s < slices; ++s) {
      m.triangles.emplace_back(ring(r, s), ring(r, s + 1), ring(r + 1, s + 1));
      m.triangles.emplace_back(ring(r, s), ring(r + 1, s + 1), ring(r + 1, s));
    }
  }
  return m;
}

}  // namespace

double TriangleMesh::area() const {
  double a = 0.0;
  for (const auto& t : triangles) {
    a += 0.5 * (vertices[t[1]] - vertices[t[0]]).cross(vertices[t[2]] - vertices[t[0]]).cast<double>().norm();
  }
  return a;
}

bool TriangleMesh::valid() const {
  const int n = static_cast<int>(vertices.size());
  for (const auto& v : vertices) {
    if (!v.allFinite()) return false;
  }
  for (const auto& t : triangles) {
    if ((t.array() < 0).any() || (t.array() >= n).any()) return false;
    if (t[0] == t[1] || t[1] == t[2] || t[0] == t[2]) return false;
    const Eigen::Vector3f cross = (vertices[t[1]] - vertices[t[0]]).cross(vertices[t[2]] - vertices[t[0]]);
    if (!(cross.norm() > 0.0f)) return false;
  }
  return !triangles.empty();
}

TriangleMesh make_box(const Eigen::Vector3d& size) {
  if (!(size.array() > 0.0).all()) throw std::invalid_argument("box size must be positive");
  TriangleMesh m;
  const Eigen::Vector3f h = (0.5 * size).cast<float>();
  for (int k = 0; k < 8; ++k) {
    m.vertices.emplace_back(k & 1 ? h.x() : -h.x(), k & 2 ? h.y() : -h.y(), k & 4 ? h.z() : -h.z());
  }
  const int faces[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4},
                           {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
  for (const auto& f : faces) {
    m.triangles.emplace_back(f[0], f[1], f[2]);
    m.triangles.emplace_back(f[0], f[2], f[3]);
  }
  orient_outward(m, [](const Eigen::Vector3f&) { return Eigen::Vector3f::Zero(); });
  return m;
}

TriangleMesh make_sphere(double radius, int slices, int stacks) {
  if (!(radius > 0.0)) throw std::invalid_argument("sphere radius must be positive");
  std::vector<std::pair<double, double>> profile;
  for (int k = 0; k <= stacks; ++k) {
    const double a = -kPi / 2 + kPi * k / stacks;
    profile.emplace_back(radius * std::sin(a), radius * std::cos(a));
  }
  TriangleMesh m = revolve(profile, slices);
  orient_outward(m, [](const Eigen::Vector3f&) { return Eigen::Vector3f::Zero(); });
  return m;
}

TriangleMesh make_capsule(double radius, double length, int slices, int stacks) {
  if (!(radius > 0.0) || !(length >= 0.0)) throw std::invalid_argument("capsule radius must be positive, length non-negative");
  std::vector<std::pair<double, double>> profile;
  for (int k = 0; k <= stacks; ++k) {  // bottom hemisphere
    const double a = -kPi / 2 + (kPi / 2) * k / stacks;
    profile.emplace_back(-0.5 * length + radius * std::sin(a), radius * std::cos(a));
  }
  for (int k = 0; k <= stacks; ++k) {  // top hemisphere
    const double a = (kPi / 2) * k / stacks;
    profile.emplace_back(0.5 * length + radius * std::sin(a), radius * std::cos(a));
  }
  TriangleMesh m = revolve(profile, slices);
  const float half = static_cast<float>(0.5 * length);
  orient_outward(m, [half](const Eigen::Vector3f& p) {
    return Eigen::Vector3f(0.0f, 0.0f, std::clamp(p.z(), -half, half));
  });
  return m;
}

TriangleMesh make_sheet(double size_x, double size_y, double thickness, int nx, int ny) {
  if (!(size_x > 0.0) || !(size_y > 0.0) || !(thickness > 0.0) || nx < 1 || ny < 1) {
    throw std::invalid_argument("sheet sizes must be positive and the grid at least 1 x 1");
  }
  TriangleMesh m;
  const int per_face = (nx + 1) * (ny + 1);
  for (int face = 0; face < 2; ++face) {
    const float z = static_cast<float>(face == 0 ? -0.5 * thickness : 0.5 * thickness);
    for (int j = 0; j <= ny; ++j) {
      for (int i = 0; i <= nx; ++i) {
        m.vertices.emplace_back(static_cast<float>(size_x * (static_cast<double>(i) / nx - 0.5)),
                                static_cast<float>(size_y * (static_cast<double>(j) / ny - 0.5)), z);
      }
    }
  }
  auto id = [&](int face, int i, int j) { return face * per_face + j * (nx + 1) + i; };
  for (int j = 0; j < ny; ++j) {
    for (int i = 0; i < nx; ++i) {
      // Front (z < 0) faces -z; back faces +z.
      m.triangles.emplace_back(id(0, i, j), id(0, i + 1, j + 1), id(0, i + 1, j));
      m.triangles.emplace_back(id(0, i, j), id(0, i, j + 1), id(0, i + 1, j + 1));
      m.triangles.emplace_back(id(1, i, j), id(1, i + 1, j), id(1, i + 1, j + 1));
      m.triangles.emplace_back(id(1, i, j), id(1, i + 1, j + 1), id(1, i, j + 1));
    }
  }
  // The rim joins the two faces along the boundary, outwards.
  auto rim = [&](int i0, int j0, int i1, int j1, const Eigen::Vector3f& out) {
    const int a = id(0, i0, j0), b = id(0, i1, j1), c = id(1, i1, j1), d = id(1, i0, j0);
    Eigen::Vector3i t1(a, b, c), t2(a, c, d);
    const Eigen::Vector3f n = (m.vertices[b] - m.vertices[a]).cross(m.vertices[c] - m.vertices[a]);
    if (n.dot(out) < 0.0f) {
      t1 = {a, c, b};
      t2 = {a, d, c};
    }
    m.triangles.push_back(t1);
    m.triangles.push_back(t2);
  };
  for (int i = 0; i < nx; ++i) {
    rim(i, 0, i + 1, 0, -Eigen::Vector3f::UnitY());
    rim(i, ny, i + 1, ny, Eigen::Vector3f::UnitY());
  }
  for (int j = 0; j < ny; ++j) {
    rim(0, j, 0, j + 1, -Eigen::Vector3f::UnitX());
    rim(nx, j, nx, j + 1, Eigen::Vector3f::UnitX());
  }
  return m;
}

void deform_sheet(const TriangleMesh& rest, double amplitude, double wavelength, double frequency,
                  double bend, double t, TriangleMesh& out) {
  out.triangles = rest.triangles;
  out.vertices.resize(rest.vertices.size());
  for (std::size_t k = 0; k < rest.vertices.size(); ++k) {
    const Eigen::Vector3f& v = rest.vertices[k];
    const double x = v.x();
    const double dz = amplitude * std::sin(2.0 * kPi * (x / wavelength - frequency * t)) + bend * x * x;
    out.vertices[k] = v + Eigen::Vector3f(0.0f, 0.0f, static_cast<float>(dz));
  }
}

TriangleMesh read_mesh(const std::string& path, double scale) {
  const aiScene* scene =
      aiImportFile(path.c_str(), aiProcess_Triangulate | aiProcess_JoinIdenticalVertices);
  if (scene == nullptr) {
    throw std::runtime_error(path + ": cannot read mesh (" + aiGetErrorString() + ")");
  }
  TriangleMesh m;
  for (unsigned k = 0; k < scene->mNumMeshes; ++k) {
    const aiMesh* mesh = scene->mMeshes[k];
    const int base = static_cast<int>(m.vertices.size());
    for (unsigned v = 0; v < mesh->mNumVertices; ++v) {
      const aiVector3D& p = mesh->mVertices[v];
      m.vertices.emplace_back(static_cast<float>(p.x * scale), static_cast<float>(p.y * scale),
                              static_cast<float>(p.z * scale));
    }
    for (unsigned f = 0; f < mesh->mNumFaces; ++f) {
      const aiFace& face = mesh->mFaces[f];
      if (face.mNumIndices == 3) {
        m.triangles.emplace_back(base + static_cast<int>(face.mIndices[0]),
                                 base + static_cast<int>(face.mIndices[1]),
                                 base + static_cast<int>(face.mIndices[2]));
      }
    }
  }
  aiReleaseImport(scene);
  if (m.triangles.empty()) throw std::runtime_error(path + ": the mesh has no triangles");
  return m;
}

}  // namespace ofv::sim
