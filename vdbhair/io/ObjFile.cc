#include "ObjFile.h"

#include <vdbhair/io/MeshFile.h>

#include <vdbhair/Version.h>
#include <vdbhair/io/FileUtil.h>
#include <vdbhair/io/TextScanner.h>

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

StrandSet readObj(const std::string& path, const ReadOptions& opts, ReadReport* report)
{
    const std::string where = "readObj(" + path + ")";
    const std::vector<char> bytes = readFileBytes(path, where, opts.interrupter);
    TextScanner text(bytes, where);

    std::vector<Vec3f> vertices;
    std::vector<Vec3f> colors;
    bool anyColor = false;
    // Each strand as a list of 0-based vertex indices, and the line it started on.
    std::vector<std::uint32_t> indices;
    std::vector<std::uint32_t> strandStart{0};
    std::vector<std::size_t> strandLine;
    std::size_t ignored = 0;
    std::vector<std::string_view> tok;

    while (text.nextLine(tok)) {
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
            const std::size_t first = indices.size();
            for (std::size_t j = 1; j < tok.size(); ++j) indices.push_back(objVertexIndex(text, tok[j], vertices.size()));
            // A chain of edges: this element starts where the previous one ended.
            const bool continues = strandStart.size() > 1 && indices[first] == indices[first - 1];
            if (continues) {
                indices.erase(indices.begin() + std::ptrdiff_t(first));  // the shared vertex
                strandStart.back() = std::uint32_t(indices.size());
            } else {
                strandLine.push_back(text.line());
                strandStart.push_back(std::uint32_t(indices.size()));
            }
        } else if (key[0] == '#') {
            continue;
        } else {
            ++ignored;  // f, vn, vt, o, g, s, usemtl, mtllib, curv, ...
        }
    }
    if (strandLine.empty()) {
        throw FormatError(where + ": no polylines: the file has no 'l' elements" +
                          (ignored ? " (" + std::to_string(ignored) + " other lines, e.g. faces, were ignored)" : std::string()));
    }
    if (ignored && report) {
        report->warnings.push_back(where + ": " + std::to_string(ignored) + " lines other than v and l (faces, normals, groups, ...) were ignored");
    }

    StrandSet out;
    out.reserve(strandLine.size(), indices.size());
    ShortStrandFilter filter(opts, report, where);
    for (std::size_t i = 0; i + 1 < strandStart.size(); ++i) {
        const std::uint32_t b = strandStart[i], e = strandStart[i + 1];
        if (!filter.keep(i, e - b, "line " + std::to_string(strandLine[i]))) continue;
        for (std::uint32_t k = b; k < e; ++k) {
            out.positions.push_back(vertices[indices[k]]);
            if (anyColor) out.color.push_back(colors[indices[k]]);
        }
        out.offsets.push_back(std::uint32_t(out.positions.size()));
    }
    filter.finish();
    return out;
}

void writeObj(const std::string& path, const StrandSet& strands)
{
    const std::string where = "writeObj(" + path + ")";
    std::string out;
    out.reserve(40 * strands.numVertices() + 8 * strands.numVertices());
    out += "# ";
    out += creatorString();
    out += ": " + std::to_string(strands.numStrands()) + " strands as polylines, root to tip\n";
    char buf[32];
    auto putFloat = [&](float v) {
        const auto res = std::to_chars(buf, buf + sizeof buf, v);
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
        out += 'l';
        for (std::size_t v = strands.begin(i); v < strands.end(i); ++v) {
            const auto res = std::to_chars(buf, buf + sizeof buf, v + 1);
            out.push_back(' ');
            out.append(buf, res.ptr);
        }
        out += '\n';
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
