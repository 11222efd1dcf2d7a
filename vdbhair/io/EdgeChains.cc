#include "EdgeChains.h"

#include <algorithm>
#include <limits>

namespace vdbhair {

StrandSet strandsFromEdges(const std::vector<Vec3f>& vertices, const std::vector<Vec3f>& colors, EdgeList& list,
                           const EdgeNaming& naming, const std::string& where, const ReadOptions& opts, ReadReport* report)
{
    std::vector<IndexEdge>& edges = list.edges;
    const bool anyColor = !colors.empty();
    auto vertexName = [&](std::uint32_t v) { return std::to_string(std::uint64_t(v) + naming.vertexBase); };
    InterruptPoll poll(opts.interrupter, where);

    // The same edge listed twice counts once; every vertex joins at most two others.
    std::stable_sort(edges.begin(), edges.end(), [](const IndexEdge& x, const IndexEdge& y) { return x.a != y.a ? x.a < y.a : x.b < y.b; });
    const std::size_t before = edges.size();
    edges.erase(std::unique(edges.begin(), edges.end(), [](const IndexEdge& x, const IndexEdge& y) { return x.a == y.a && x.b == y.b; }), edges.end());
    if (report && (before != edges.size() || list.selfEdges)) {
        report->warnings.push_back(where + ": ignored " + std::to_string(before - edges.size()) + " repeated edge(s) and " +
                                   std::to_string(list.selfEdges) + " edge(s) from a vertex to itself");
    }
    constexpr std::uint32_t kNone = std::numeric_limits<std::uint32_t>::max();
    const std::size_t nV = vertices.size();
    std::vector<std::uint32_t> adj(2 * nV, kNone);  // the (at most two) neighbours of each vertex
    std::vector<std::uint32_t> adjPlace(2 * nV, 0);
    std::vector<std::uint8_t> degree(nV, 0);
    auto link = [&](std::uint32_t v, std::uint32_t w, std::uint32_t place) {
        if (degree[v] == 2) {
            throw FormatError(where + ": vertex " + vertexName(v) + " joins 3 or more others (" + naming.places + " " +
                              std::to_string(adjPlace[2 * v]) + ", " + std::to_string(adjPlace[2 * v + 1]) + " and " +
                              std::to_string(place) + "); a strand cannot branch, so every vertex may join at most two");
        }
        adj[2 * v + degree[v]] = w;
        adjPlace[2 * v + degree[v]] = place;
        ++degree[v];
    };
    for (const IndexEdge& e : edges) {
        link(e.a, e.b, e.place);
        link(e.b, e.a, e.place);
    }
    std::vector<std::uint32_t> singlePlace(nV, 0);
    for (const auto& [v, place] : list.singles) if (degree[v] == 0 && singlePlace[v] == 0) singlePlace[v] = place;

    // Walk each chain from its lower-index end; strands in the order of that end.
    StrandSet out;
    out.reserve(edges.size() ? nV - std::min(nV, edges.size()) : list.singles.size(), nV);
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
            if (singlePlace[v] == 0) continue;  // a vertex no element uses
            chain.push_back(v);
            location = naming.place + " " + std::to_string(singlePlace[v]);
        } else if (degree[v] == 1) {
            location = naming.place + " " + std::to_string(adjPlace[2 * v]);
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
            throw FormatError(where + ": vertex " + vertexName(v) + " lies on a closed loop of edges (" + naming.place + " " +
                              std::to_string(adjPlace[2 * v]) + "); a strand needs two ends, a root and a tip");
        }
    }
    filter.finish();
    return out;
}

} // namespace vdbhair
