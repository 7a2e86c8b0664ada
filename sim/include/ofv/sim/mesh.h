/**
 * \file mesh.h
 * \brief Triangle meshes of the simulated world: primitive shapes, a
 *        deformable sheet, and meshes read from files (OBJ, PLY, STL, ... via Assimp).
 *
 * Vertices are in the body's own frame [m]; triangles are counter-clockwise
 * seen from outside (outward normals).
 */
#pragma once

#include <Eigen/Geometry>

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace ofv::sim {

/// \brief An indexed triangle mesh in its body frame [m].
struct TriangleMesh {
  std::vector<Eigen::Vector3f> vertices;   ///< body frame [m]
  std::vector<Eigen::Vector3i> triangles;  ///< vertex indices, counter-clockwise from outside

  /// \brief Total surface area [m^2].
  [[nodiscard]] double area() const;
  /// \brief True when every index is in range and no triangle is degenerate or non-finite.
  [[nodiscard]] bool valid() const;
};

/// \brief Box centred on the origin with edge lengths `size` [m].
[[nodiscard]] TriangleMesh make_box(const Eigen::Vector3d& size);
/// \brief Sphere centred on the origin (UV sphere).
[[nodiscard]] TriangleMesh make_sphere(double radius, int slices = 24, int stacks = 12);
/// \brief Capsule along the body z axis: a cylinder of `length` between two hemispheres.
[[nodiscard]] TriangleMesh make_capsule(double radius, double length, int slices = 20, int stacks = 8);
/**
 * \brief Thin sheet in the body xy plane, facing -z (towards a camera that looks
 *        along +z), of size x by y [m] with thickness `thickness` and a grid of
 *        nx x ny cells on each face.
 */
[[nodiscard]] TriangleMesh make_sheet(double size_x, double size_y, double thickness, int nx, int ny);
/// \brief Largest mesh read_mesh() reads: vertices, triangles (PLY faces) and file size.
constexpr std::size_t kMaxMeshVertices = 5'000'000;
/// \brief Most triangles (PLY faces) read_mesh() reads.
constexpr std::size_t kMaxMeshTriangles = 10'000'000;
/// \brief Largest mesh file read_mesh() reads [bytes] (512 MiB).
constexpr std::uintmax_t kMaxMeshFileBytes = std::uintmax_t{512} << 20;

/**
 * \brief Reads a mesh file (any format Assimp reads), scaled by `scale`.
 *
 * A PLY file's header is checked before Assimp reads it (element counts
 * within the limits and inside the file size); every scaled vertex must be
 * finite and within 10 km of the origin.
 * \throws std::runtime_error naming the file when it cannot be read, breaks these
 * limits or has no triangles.
 */
[[nodiscard]] TriangleMesh read_mesh(const std::string& path, double scale = 1.0);

/**
 * \brief Bends a sheet made by make_sheet(): each vertex moves along the
 *        sheet normal (body z) by a travelling wave plus a bend,
 *        `dz = amplitude sin(2 pi (x / wavelength - frequency t)) + bend x^2`.
 *        Topology is unchanged, so the mesh stays valid.
 */
void deform_sheet(const TriangleMesh& rest, double amplitude, double wavelength, double frequency,
                  double bend, double t, TriangleMesh& out);

}  // namespace ofv::sim
