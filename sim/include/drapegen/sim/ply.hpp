#pragma once
// Cloth meshes as PLY files (Turk's polygon file format): positions, rest coordinates and the material angle.

#include <string>

#include "drapegen/sim/expected.hpp"
#include "drapegen/sim/mesh.hpp"

namespace drapegen::sim {

/// Writes `mesh` as a binary_little_endian PLY file:
///
///   comment material_angle <radians>       (shortest text that reads back to the same double)
///   element vertex N: property double x y z (positions) and u v (rest coordinates)
///   element face T:   property list uchar int vertex_indices
///
/// The file is written to a temporary of its own (`path.tmp.PID.N`), flushed to disk and then renamed over `path`,
/// so a crash leaves either the old file or the complete new one (plus possibly a stale temporary). Fails, naming
/// the path and the system's reason, if the file cannot be written, and without touching the disk if the mesh is
/// inconsistent (size mismatch, index out of range, non-finite value, no triangles): it never writes a file that
/// read_ply would reject.
[[nodiscard]] Status write_ply(const std::string& path, const ClothMesh& mesh);

/// Reads a PLY file in ascii or binary_little_endian format.
///
/// Required: a `vertex` element with scalar properties x y z (any scalar type, usually float or double) and a
/// non-empty `face` element whose list property `vertex_indices` (or `vertex_index`) holds triangles only.
/// Optional: vertex properties u v, taken as the rest coordinates; when a file has neither, the rest coordinates are
/// the file's (x, y), which is right only for a specimen stored flat in its rest state. A comment line
/// `comment material_angle <radians>` sets ClothMesh::material_angle (default 0). Other elements and properties are
/// skipped. Triangles are taken as they are: their rest orientation is not checked or changed.
///
/// Every failure is returned as an Error naming the file and the problem: missing or unreadable file, malformed
/// header, unsupported format (binary_big_endian), truncated or malformed data, non-triangular faces, vertex indices
/// out of range, non-finite coordinates, no faces.
[[nodiscard]] Expected<ClothMesh> read_ply(const std::string& path);

}  // namespace drapegen::sim
