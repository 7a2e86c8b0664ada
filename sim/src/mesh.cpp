// Triangle meshes: primitives, the deformable sheet, files through Assimp.
#include "ofv/sim/mesh.h"
#include "ofv/constants.h"

#include <assimp/cimport.h>
#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include <cctype>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <sstream>
#include <stdexcept>

namespace ofv::sim {

namespace {

/**
 * Checks a PLY header before Assimp reads the file (Assimp aborts on truncated
 * files and spends minutes on headers that claim 10^8 vertices): the element
 * counts within the limits, and count x the fewest bytes of an element (a face
 * has 3 indices at least) inside the file.
 */
void check_ply_header(const std::string& path) {
  const auto fail = [&](const std::string& what) {
    throw std::runtime_error(path + ": invalid PLY header: " + what);
  };
  std::ifstream in(path, std::ios::binary);
  std::string line, format;
  std::getline(in, line);
  if (line != "ply" && line != "ply\r") fail("the first line is not 'ply'");
  struct Element {
    std::string name;
    std::uint64_t count = 0;
    std::uint64_t min_bytes = 0;
  };
  std::vector<Element> elements;
  const std::map<std::string, std::uint64_t> sizes{
      {"char", 1},  {"uchar", 1},  {"int8", 1},    {"uint8", 1},   {"short", 2},
      {"ushort", 2}, {"int16", 2}, {"uint16", 2},  {"int", 4},     {"uint", 4},
      {"int32", 4},  {"uint32", 4}, {"float", 4},  {"float32", 4}, {"double", 8},
      {"float64", 8}};
  const auto size_of = [&](const std::string& type) {
    const auto it = sizes.find(type);
    if (it == sizes.end()) fail("unknown property type '" + type.substr(0, 20) + "'");
    return it->second;
  };
  while (std::getline(in, line) && line.rfind("end_header", 0) != 0) {
    if (in.tellg() > 65536) fail("no end_header in the first 64 KiB");
    std::istringstream words(line);
    std::string key;
    words >> key;
    if (key == "format") {
      words >> format;
    } else if (key == "element") {
      Element e;
      std::string count;
      words >> e.name >> count;
      if (count.empty() || count.size() > 12 || count.find_first_not_of("0123456789") != std::string::npos) {
        fail("element " + e.name.substr(0, 20) + ": count '" + count.substr(0, 20) + "'");
      }
      e.count = std::stoull(count);
      elements.push_back(e);
    } else if (key == "property") {
      if (elements.empty()) fail("a property before any element");
      Element& e = elements.back();
      std::string type, count_type, item_type, name;
      words >> type;
      const bool ascii = format == "ascii";
      if (type == "list") {
        words >> count_type >> item_type >> name;
        const std::uint64_t items = name == "vertex_indices" || name == "vertex_index" ? 3 : 0;
        e.min_bytes += ascii ? 2 + 2 * items : size_of(count_type) + items * size_of(item_type);
      } else {
        e.min_bytes += ascii ? 2 : size_of(type);
      }
    }
  }
  if (!in) fail("no end_header");
  if (format != "ascii" && format != "binary_little_endian" && format != "binary_big_endian") {
    fail("format '" + format.substr(0, 30) + "'");
  }
  const auto start = static_cast<std::uint64_t>(in.tellg());
  const std::uint64_t file_size = std::filesystem::file_size(path);
  std::uint64_t needed = 0;
  for (const Element& e : elements) {
    const std::uint64_t limit = e.name == "vertex" ? kMaxMeshVertices : kMaxMeshTriangles;
    if (e.count > limit) {
      fail("element " + e.name.substr(0, 20) + " " + std::to_string(e.count) + ": more than " +
           std::to_string(limit));
    }
    needed += e.count * e.min_bytes;  // <= 10^7 x (properties x 8): no overflow
  }
  if (needed > file_size - start) {
    fail("the elements need " + std::to_string(needed) + " bytes at least, the file has " +
         std::to_string(file_size - start) + " after the header");
  }
}


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
  std::error_code ec;
  const std::uintmax_t bytes = std::filesystem::file_size(path, ec);
  if (ec) throw std::runtime_error(path + ": cannot read mesh (" + ec.message() + ")");
  if (bytes > kMaxMeshFileBytes) {
    throw std::runtime_error(path + ": " + std::to_string(bytes) + " bytes, more than " +
                             std::to_string(kMaxMeshFileBytes));
  }
  std::string extension = std::filesystem::path(path).extension().string();
  for (char& c : extension) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  if (extension == ".ply") check_ply_header(path);
  const aiScene* scene = aiImportFile(
      path.c_str(), aiProcess_Triangulate | aiProcess_JoinIdenticalVertices | aiProcess_ValidateDataStructure);
  if (scene == nullptr) {
    throw std::runtime_error(path + ": cannot read mesh (" + aiGetErrorString() + ")");
  }
  TriangleMesh m;
  std::string problem;
  for (unsigned k = 0; k < scene->mNumMeshes && problem.empty(); ++k) {
    const aiMesh* mesh = scene->mMeshes[k];
    const int base = static_cast<int>(m.vertices.size());
    if (m.vertices.size() + mesh->mNumVertices > kMaxMeshVertices) {
      problem = "more than " + std::to_string(kMaxMeshVertices) + " vertices";
      break;
    }
    for (unsigned v = 0; v < mesh->mNumVertices; ++v) {
      const aiVector3D& p = mesh->mVertices[v];
      const Eigen::Vector3f q(static_cast<float>(p.x * scale), static_cast<float>(p.y * scale),
                              static_cast<float>(p.z * scale));
      if (!q.allFinite() || q.cwiseAbs().maxCoeff() > 1e4f) {  // Embree aborts on NaN and inf
        problem = "vertex " + std::to_string(v) + " (" + std::to_string(p.x) + ", " +
                  std::to_string(p.y) + ", " + std::to_string(p.z) + ") x scale " +
                  std::to_string(scale) + " is not finite or beyond 10 km";
        break;
      }
      m.vertices.push_back(q);
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
  if (!problem.empty()) throw std::runtime_error(path + ": " + problem);
  if (m.triangles.empty()) throw std::runtime_error(path + ": the mesh has no triangles");
  return m;
}

}  // namespace ofv::sim
