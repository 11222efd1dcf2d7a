/// @file EdgeChains.h
/// @brief Strands rebuilt from undirected edges between indexed vertices: what the OBJ reader
/// does with `l` elements (Blender exports them unchained) and the PLY reader with an `edge`
/// element (Open3D and trimesh line sets). One chaining for every format.
///
/// Each connected chain of edges is one strand, rooted at its end with the lower vertex index (or,
/// with ReadOptions::objRootNear, at the end nearest that point); strands are ordered by the index
/// of that lower end, which reproduces the order of every file vdbhair writes. The same edge
/// listed twice counts once and an edge from a vertex to itself is ignored (both counted in one
/// warning). A vertex joined to three or more others (a branch) and a closed loop are errors
/// naming the vertex (numbered as in the file) and the places of the edges involved.
#pragma once

#include <vdbhair/io/ReadOptions.h>
#include <vdbhair/strands/StrandSet.h>

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

namespace vdbhair {

/// One edge as read: its vertices (0-based, a < b) and its place in the file (a line number, an
/// edge's item number), which messages name.
struct IndexEdge
{
    std::uint32_t a, b;
    std::uint32_t place;
};

/// How a format numbers vertices and names places in messages.
struct EdgeNaming
{
    std::uint32_t vertexBase = 0;     ///< 1 for OBJ (1-based indices), 0 for PLY
    std::string place = "edge";       ///< one place: "line" (OBJ) or "edge" (PLY)
    std::string places = "edges";     ///< several, after "(": "edges on lines" (OBJ) or "edges" (PLY)
};

/// What a reader collected for strandsFromEdges().
struct EdgeList
{
    std::vector<IndexEdge> edges;
    /// (vertex, place) of one-vertex elements (OBJ `l 5`): a one-vertex strand when no edge uses it
    std::vector<std::pair<std::uint32_t, std::uint32_t>> singles;
    std::size_t selfEdges = 0;  ///< edges from a vertex to itself, skipped while reading
};

/// @brief Chain @a list's edges into strands of @a vertices (with @a colors when not empty).
/// @param list its edges are sorted and deduplicated in place
/// @param where message prefix, e.g. "readObj(a.obj)"
/// @throw FormatError for a branching vertex, a closed loop, or a short strand under
/// ShortStrandPolicy::Reject; InterruptedError.
StrandSet strandsFromEdges(const std::vector<Vec3f>& vertices, const std::vector<Vec3f>& colors, EdgeList& list,
                           const EdgeNaming& naming, const std::string& where, const ReadOptions& opts, ReadReport* report);

} // namespace vdbhair
