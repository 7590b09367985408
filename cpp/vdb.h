// OpenVDB side of the bridge: sparse narrow-band level sets, built from leaf blocks sampled in
// Rust or from triangles, smoothed, meshed with volumeToMesh and written as .vdb. Only plain
// slices and opaque handles cross the boundary. One header for the whole library; the
// definitions live in one small translation unit per operation (vdb_grid.cc, vdb_from_mesh.cc,
// vdb_filter.cc, vdb_mesh.cc), which share vdb_internal.h.
#pragma once
#include <cstdint>
#include <memory>
#include "rust/cxx.h"

namespace latvox {

// Opaque handle: the OpenVDB grid lives in Impl, defined only in vdb_internal.h.
struct VdbGrid {
  struct Impl;
  std::unique_ptr<Impl> impl;
  VdbGrid();
  ~VdbGrid();
};

// A .vdb file being put together: named grids, written at once.
struct VdbFile {
  struct Impl;
  std::unique_ptr<Impl> impl;
  VdbFile();
  ~VdbFile();
};

struct Extraction;
struct DenseValues;
enum class SmoothingMode : uint8_t;

// vdb_grid.cc: the grid and what it holds.
void vdb_set_threads(std::size_t threads);

std::unique_ptr<VdbGrid> vdb_grid_from_leaves(double voxel_size, rust::Slice<const double> origin,
                                              float half_width,
                                              rust::Slice<const int32_t> leaf_origins,
                                              rust::Slice<const float> values,
                                              rust::Slice<const int32_t> inside_tiles);

uint64_t vdb_active_voxels(const VdbGrid& grid);
// The origins of the grid's leaf nodes (xyz triples, index space).
rust::Vec<int32_t> vdb_leaf_origins(const VdbGrid& grid);
uint64_t vdb_memory_bytes(const VdbGrid& grid);
void vdb_write(const VdbGrid& grid, rust::Str path);

// vdb_from_mesh.cc: triangles to a signed distance field (meshToSignedDistanceField), bands
// in voxels outside and inside; index (0,0,0) at the origin.
std::unique_ptr<VdbGrid> vdb_grid_from_mesh(rust::Slice<const float> positions,
                                            rust::Slice<const uint32_t> indices,
                                            double voxel_size, float exterior_width,
                                            float interior_width);

// vdb_probe.cc: the grid's values at world points (xyz triples), trilinear between voxels.
std::unique_ptr<VdbGrid> vdb_csg(const VdbGrid& a, const VdbGrid& b, bool difference);
void vdb_probe(const VdbGrid& grid, rust::Slice<const double> points, rust::Slice<float> values);

// vdb_filter.cc: the level set rebuilt as a signed distance `half_width` voxels each side of
// the surface, then `iterations` passes of LevelSetFilter.
std::unique_ptr<VdbGrid> vdb_smoothed(const VdbGrid& grid, SmoothingMode mode,
                                      uint32_t iterations, float half_width);

// vdb_mesh.cc: the iso-surface `isovalue` (world units) as outward-wound triangles, and the
// zero iso-surface in index space with every point tied to its voxel.
void vdb_volume_to_mesh(const VdbGrid& grid, double isovalue, double adaptivity,
                        rust::Vec<float>& positions, rust::Vec<uint32_t>& indices);

void vdb_extract(const VdbGrid& grid, Extraction& out);

// vdb_file.cc: grids of plain values (NaN: inactive), and files of several named grids.
std::unique_ptr<VdbGrid> vdb_values_from_leaves(double voxel_size, rust::Slice<const double> origin,
                                                float background, bool fog,
                                                rust::Slice<const int32_t> leaf_origins,
                                                rust::Slice<const float> values);
std::unique_ptr<VdbFile> vdb_file_new();
void vdb_file_add(VdbFile& file, const VdbGrid& grid, rust::Str name);
void vdb_file_write(const VdbFile& file, rust::Str path);
void vdb_read_dense(rust::Str path, uint64_t max_values, DenseValues& out);

}  // namespace latvox
