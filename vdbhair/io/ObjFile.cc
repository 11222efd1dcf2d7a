#include "ObjFile.h"

#include <vdbhair/Memory.h>
#include <vdbhair/io/MeshFile.h>

#include <vdbhair/Version.h>
#include <vdbhair/io/FileUtil.h>
#include <vdbhair/io/TextScanner.h>

#include <algorithm>
#include <charconv>
#include <limits>

namespace vdbhair {

namespace {

/// The position on a 'v' line (vertex number @a index, for the error message).
Vec3f objPosition(TextScanner& text, const std::vector<std::string_view>& tok, std::size_t index, const std::string& where)
{
    if (tok.size() < 4) text.fail("a 'v' line needs 3 coordinates, got " + std::to_string(tok.size() - 1));
    const Vec3f p(text.toFloat(tok[1], "x"), text.toFloat(tok[2], "y"), text.toFloat(tok[3], "z"));
    checkFinite(p, index, where, "line " + std::to_string(text.line()));
    return p;
}

/// The 0-based vertex an index token names ("i", "i/t", "i//n", "i/t/n"; 1-based, negative
/// counting back from the @a defined vertices so far).
std::uint32_t objVertexIndex(TextScanner& text, std::string_view t, std::size_t defined)
{
    if (const std::size_t slash = t.find('/'); slash != std::string_view::npos) t = t.substr(0, slash);
    const std::int64_t idx = text.toInt(t, "vertex index");
    const std::int64_t n = std::int64_t(defined);
    const std::int64_t resolved = idx > 0 ? idx - 1 : n + idx;
    if (idx == 0 || resolved < 0 || resolved >= n) {
        text.fail("vertex index " + std::to_string(idx) + " is out of range: " + std::to_string(n) +
                  " vertices are defined so far (1-based, negative counts back)");
    }
    return std::uint32_t(resolved);
}

} // namespace

ObjLineStyle objLineStyleFromName(const std::string& name)
{
    if (name == "edges") return ObjLineStyle::Edges;
    if (name == "polylines") return ObjLineStyle::Polylines;
    throw ValueError("OBJ line style '" + name + "' is not one of edges (Blender), polylines (Houdini)");
}

StrandSet readObj(const std::string& path, const ReadOptions& opts, ReadReport* report)
{
    const std::string where = "readObj(" + path + ")";
    const std::vector<char> bytes = readFileBytes(path, where, opts.interrupter);
    TextScanner text(bytes, where);

    // Pass 1: vertices, and every `l` element as edges between consecutive vertices.
    std::vector<Vec3f> vertices;
    std::vector<Vec3f> colors;
    bool anyColor = false;
    struct Edge { std::uint32_t a, b; std::uint32_t line; };
    std::vector<Edge> edges;
    std::vector<std::pair<std::uint32_t, std::uint32_t>> singles;  // (vertex, line) of one-vertex elements
    std::size_t lineElements = 0, ignored = 0, selfEdges = 0;
    std::vector<std::string_view> tok;
    std::vector<std::uint32_t> element;

    InterruptPoll poll(opts.interrupter, where);
    while (text.nextLine(tok)) {
        poll();
        if (tok.empty()) continue;
        const std::string_view key = tok[0];
        if (key == "v") {
            vertices.push_back(objPosition(text, tok, vertices.size(), where));
            Vec3f c(0.5f);
            if (tok.size() >= 7) {
                c = Vec3f(text.toFloat(tok[4], "red"), text.toFloat(tok[5], "green"), text.toFloat(tok[6], "blue"));
                anyColor = true;
            }
            colors.push_back(c);
        } else if (key == "l") {
            if (tok.size() < 2) text.fail("an 'l' element needs at least one vertex index");
            ++lineElements;
            element.clear();
            for (std::size_t j = 1; j < tok.size(); ++j) element.push_back(objVertexIndex(text, tok[j], vertices.size()));
            const std::uint32_t line = std::uint32_t(std::min<std::size_t>(text.line(), 0xffffffffu));
            if (element.size() == 1) singles.push_back({element[0], line});
            for (std::size_t j = 0; j + 1 < element.size(); ++j) {
                if (element[j] == element[j + 1]) { ++selfEdges; continue; }
                edges.push_back({std::min(element[j], element[j + 1]), std::max(element[j], element[j + 1]), line});
            }
        } else if (key[0] == '#') {
            continue;
        } else {
            ++ignored;  // f, vn, vt, o, g, s, usemtl, mtllib, curv, ...
        }
    }
    if (lineElements == 0) {
        throw FormatError(where + ": no polylines: the file has no 'l' elements" +
                          (ignored ? " (" + std::to_string(ignored) + " other lines, e.g. faces, were ignored)" : std::string()));
    }
    if (ignored && report) {
        report->warnings.push_back(where + ": " + std::to_string(ignored) + " lines other than v and l (faces, normals, groups, ...) were ignored");
    }

    // Pass 2: the same edge listed twice counts once; every vertex joins at most two others.
    std::stable_sort(edges.begin(), edges.end(), [](const Edge& x, const Edge& y) { return x.a != y.a ? x.a < y.a : x.b < y.b; });
    const std::size_t before = edges.size();
    edges.erase(std::unique(edges.begin(), edges.end(), [](const Edge& x, const Edge& y) { return x.a == y.a && x.b == y.b; }), edges.end());
    if (report && (before != edges.size() || selfEdges)) {
        report->warnings.push_back(where + ": ignored " + std::to_string(before - edges.size()) + " repeated edge(s) and " +
                                   std::to_string(selfEdges) + " edge(s) from a vertex to itself");
    }
    constexpr std::uint32_t kNone = std::numeric_limits<std::uint32_t>::max();
    const std::size_t nV = vertices.size();
    std::vector<std::uint32_t> adj(2 * nV, kNone);  // the (at most two) neighbours of each vertex
    std::vector<std::uint32_t> adjLine(2 * nV, 0);
    std::vector<std::uint8_t> degree(nV, 0);
    auto link = [&](std::uint32_t v, std::uint32_t w, std::uint32_t line) {
        if (degree[v] == 2) {
            throw FormatError(where + ": vertex " + std::to_string(v + 1) + " joins 3 or more others (edges on lines " +
                              std::to_string(adjLine[2 * v]) + ", " + std::to_string(adjLine[2 * v + 1]) + " and " +
                              std::to_string(line) + "); a strand cannot branch, so every vertex may join at most two");
        }
        adj[2 * v + degree[v]] = w;
        adjLine[2 * v + degree[v]] = line;
        ++degree[v];
    };
    for (const Edge& e : edges) {
        link(e.a, e.b, e.line);
        link(e.b, e.a, e.line);
    }
    std::vector<std::uint32_t> singleLine(nV, 0);
    for (const auto& [v, line] : singles) if (degree[v] == 0 && singleLine[v] == 0) singleLine[v] = line;

    // Pass 3: walk each chain from its lower-index end; strands in the order of that end.
    StrandSet out;
    out.reserve(edges.size() ? nV - edges.size() : singles.size(), nV);
    ShortStrandFilter filter(opts, report, where);
    std::vector<char> visited(nV, 0);
    std::vector<std::uint32_t> chain;
    std::size_t strand = 0;
    for (std::uint32_t v = 0; v < nV; ++v) {
        poll();
        if (visited[v]) continue;
        chain.clear();
        std::string location;
        if (degree[v] == 0) {
            if (singleLine[v] == 0) continue;  // a vertex no line element uses
            chain.push_back(v);
            location = "line " + std::to_string(singleLine[v]);
        } else if (degree[v] == 1) {
            location = "line " + std::to_string(adjLine[2 * v]);
            std::uint32_t prev = kNone, cur = v;
            while (cur != kNone) {
                visited[cur] = 1;
                chain.push_back(cur);
                const std::uint32_t next = adj[2 * cur] != prev ? adj[2 * cur] : adj[2 * cur + 1];
                prev = cur;
                cur = (next != kNone && !visited[next]) ? next : kNone;
            }
        } else {
            continue;  // inside a chain (reached from its end) or on a loop (found below)
        }
        visited[v] = 1;
        if (opts.objRootNear && chain.size() >= 2) {
            const Vec3f& p = *opts.objRootNear;
            if ((vertices[chain.back()] - p).lengthSqr() < (vertices[chain.front()] - p).lengthSqr()) {
                std::reverse(chain.begin(), chain.end());
            }
        }
        if (filter.keep(strand++, chain.size(), location)) {
            for (const std::uint32_t w : chain) {
                out.positions.push_back(vertices[w]);
                if (anyColor) out.color.push_back(colors[w]);
            }
            out.offsets.push_back(std::uint32_t(out.positions.size()));
        }
    }
    for (std::uint32_t v = 0; v < nV; ++v) {
        if (degree[v] == 2 && !visited[v]) {
            throw FormatError(where + ": vertex " + std::to_string(v + 1) + " lies on a closed loop of edges (line " +
                              std::to_string(adjLine[2 * v]) + "); a strand needs two ends, a root and a tip");
        }
    }
    filter.finish();
    return out;
}

void writeObj(const std::string& path, const StrandSet& strands, ObjLineStyle style)
{
    const std::string where = "writeObj(" + path + ")";
    std::string out;
    reserveHugePages(out, 40 * strands.numVertices() + 16 * strands.numVertices());
    out += "# ";
    out += creatorString();
    out += ": " + std::to_string(strands.numStrands()) + " strands, " + std::to_string(strands.numVertices()) +
           " vertices, root to tip, +Y up; " +
           (style == ObjLineStyle::Edges ? "one two-vertex 'l' edge per segment, chained per strand (Blender reads every segment)\n"
                                         : "one 'l' polyline per strand\n");
    char buf[32];
    auto putFloat = [&](float v) {
        const auto res = std::to_chars(buf, buf + sizeof buf, v);
        out.push_back(' ');
        out.append(buf, res.ptr);
    };
    auto putIndex = [&](std::size_t v) {
        const auto res = std::to_chars(buf, buf + sizeof buf, v + 1);
        out.push_back(' ');
        out.append(buf, res.ptr);
    };
    const bool hasColor = !strands.color.empty();
    for (std::size_t v = 0; v < strands.numVertices(); ++v) {
        out += 'v';
        for (int c = 0; c < 3; ++c) putFloat(strands.positions[v][c]);
        if (hasColor) for (int c = 0; c < 3; ++c) putFloat(strands.color[v][c]);
        out += '\n';
    }
    for (std::size_t i = 0; i < strands.numStrands(); ++i) {
        if (style == ObjLineStyle::Edges) {
            for (std::size_t v = strands.begin(i); v + 1 < strands.end(i); ++v) {
                out += 'l';
                putIndex(v);
                putIndex(v + 1);
                out += '\n';
            }
        } else {
            out += 'l';
            for (std::size_t v = strands.begin(i); v < strands.end(i); ++v) putIndex(v);
            out += '\n';
        }
    }
    writeFileAtomic(path, out, where);
}

TriangleMesh readObjMesh(const std::string& path)
{
    const std::string where = "readObjMesh(" + path + ")";
    const std::vector<char> bytes = readFileBytes(path, where);
    TextScanner text(bytes, where);
    TriangleMesh mesh;
    std::vector<std::string_view> tok;
    std::vector<std::uint32_t> face;
    while (text.nextLine(tok)) {
        if (tok.empty()) continue;
        if (tok[0] == "v") {
            mesh.vertices.push_back(objPosition(text, tok, mesh.vertices.size(), where));
        } else if (tok[0] == "f") {
            if (tok.size() < 4) text.fail("an 'f' line needs at least 3 vertices, got " + std::to_string(tok.size() - 1));
            face.clear();
            for (std::size_t j = 1; j < tok.size(); ++j) face.push_back(objVertexIndex(text, tok[j], mesh.vertices.size()));
            for (std::size_t j = 1; j + 1 < face.size(); ++j) mesh.triangles.push_back({face[0], face[j], face[j + 1]});
        }
    }
    if (mesh.triangles.empty()) throw FormatError(where + ": the file has no faces ('f' lines)");
    return mesh;
}

} // namespace vdbhair
