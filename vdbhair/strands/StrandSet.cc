#include "StrandSet.h"

#include <vdbhair/Exceptions.h>
#include <vdbhair/Memory.h>

#include <cmath>
#include <cstdlib>
#include <limits>

namespace vdbhair {

void StrandSet::addStrand(const Vec3f* points, std::size_t count)
{
    const std::size_t total = positions.size() + count;
    if (total > std::numeric_limits<std::uint32_t>::max()) {
        throw ValueError("StrandSet::addStrand: " + std::to_string(total) +
                         " vertices exceed the limit of 2^32-1 vertices per set");
    }
    positions.insert(positions.end(), points, points + count);
    offsets.push_back(static_cast<std::uint32_t>(total));
    if (!thickness.empty()) thickness.resize(total, defaults.thickness);
    if (!transparency.empty()) transparency.resize(total, defaults.transparency);
    if (!color.empty()) color.resize(total, defaults.color);
    if (!rootUV.empty()) rootUV.resize(numStrands(), Vec2f(0.f));
    if (!strandId.empty()) strandId.push_back(static_cast<std::int32_t>(numStrands() - 1));
}

void StrandSet::clear()
{
    positions.clear();
    offsets.assign(1, 0);
    thickness.clear();
    transparency.clear();
    color.clear();
    rootUV.clear();
    strandId.clear();
}

void StrandSet::reserve(std::size_t strands, std::size_t vertices)
{
    reserveHugePages(positions, vertices);  // a fresh set's positions fault in 2 MiB at a time (Memory.h)
    reserveHugePages(offsets, strands + 1);
}

void StrandSet::validate(const std::string& where) const
{
    auto fail = [&](const std::string& msg) { throw FormatError(where + ": " + msg); };
    if (offsets.empty() || offsets.front() != 0) fail("offsets must start at 0");
    if (offsets.back() != positions.size()) {
        fail("offsets end at " + std::to_string(offsets.back()) + " but there are " +
             std::to_string(positions.size()) + " vertices");
    }
    const std::size_t nS = numStrands(), nV = numVertices();
    for (std::size_t i = 0; i < nS; ++i) {
        if (offsets[i + 1] < offsets[i] + 2) {
            fail("strand " + std::to_string(i) + " has " +
                 std::to_string(int64_t(offsets[i + 1]) - int64_t(offsets[i])) +
                 " vertices; a strand needs at least 2");
        }
    }
    for (std::size_t v = 0; v < nV; ++v) {
        const Vec3f& p = positions[v];
        if (!std::isfinite(p.x()) || !std::isfinite(p.y()) || !std::isfinite(p.z())) {
            fail("vertex " + std::to_string(v) + " has a non-finite coordinate");
        }
    }
    auto checkSize = [&](std::size_t got, std::size_t want, const char* name) {
        if (got != 0 && got != want) {
            fail(std::string(name) + " has " + std::to_string(got) + " entries, expected " +
                 std::to_string(want));
        }
    };
    checkSize(thickness.size(), nV, "thickness");
    checkSize(transparency.size(), nV, "transparency");
    checkSize(color.size(), nV, "color");
    checkSize(rootUV.size(), nS, "rootUV");
    checkSize(strandId.size(), nS, "strandId");
}

void StrandSet::append(const StrandSet& other)
{
    const std::size_t nV0 = numVertices(), nS0 = numStrands();
    const std::size_t nV = nV0 + other.numVertices(), nS = nS0 + other.numStrands();
    if (nV > std::numeric_limits<std::uint32_t>::max()) {
        throw ValueError("StrandSet::append: " + std::to_string(nV) +
                         " vertices exceed the limit of 2^32-1 vertices per set");
    }
    if (empty()) {
        defaults = other.defaults;
        metersPerUnit = other.metersPerUnit;
        upAxis = other.upAxis;
    } else {
        // Declared space: kept where both sides agree, unknown where they differ.
        if (metersPerUnit != other.metersPerUnit) metersPerUnit = 0.0;
        if (upAxis != other.upAxis) upAxis = 0;
    }
    positions.insert(positions.end(), other.positions.begin(), other.positions.end());
    for (std::size_t i = 1; i < other.offsets.size(); ++i) {
        offsets.push_back(static_cast<std::uint32_t>(nV0 + other.offsets[i]));
    }
    // Attributes: keep an array if either side has it, filling the other side with defaults.
    auto merge = [&](auto& mine, const auto& theirs, std::size_t n0, std::size_t n, auto defMine,
                     auto defTheirs) {
        if (mine.empty() && theirs.empty()) return;
        mine.resize(n0, defMine);
        if (theirs.empty()) mine.resize(n, defTheirs);
        else mine.insert(mine.end(), theirs.begin(), theirs.end());
    };
    merge(thickness, other.thickness, nV0, nV, defaults.thickness, other.defaults.thickness);
    merge(transparency, other.transparency, nV0, nV, defaults.transparency,
          other.defaults.transparency);
    merge(color, other.color, nV0, nV, defaults.color, other.defaults.color);
    merge(rootUV, other.rootUV, nS0, nS, Vec2f(0.f), Vec2f(0.f));
    if (!strandId.empty() || !other.strandId.empty()) {
        for (std::size_t i = strandId.size(); i < nS0; ++i) strandId.push_back(std::int32_t(i));
        for (std::size_t i = 0; i < other.numStrands(); ++i) {
            strandId.push_back(other.strandId.empty() ? std::int32_t(nS0 + i) : other.strandId[i]);
        }
    }
}

void StrandSet::append(StrandSet&& other)
{
    if (empty() && offsets.size() == 1 && positions.empty()) {
        // What append(other) builds from an empty set: other's strands, attributes and defaults.
        *this = std::move(other);
        return;
    }
    append(static_cast<const StrandSet&>(other));
}

StrandSet selectStrands(const StrandSet& strands, const std::vector<char>& keep)
{
    StrandSet out;
    out.defaults = strands.defaults;
    out.metersPerUnit = strands.metersPerUnit;
    out.upAxis = strands.upAxis;
    const bool hasT = !strands.thickness.empty(), hasA = !strands.transparency.empty(),
               hasC = !strands.color.empty(), hasUV = !strands.rootUV.empty(),
               hasId = !strands.strandId.empty();
    for (std::size_t i = 0; i < strands.numStrands(); ++i) {
        if (!keep[i]) continue;
        const std::size_t b = strands.begin(i), e = strands.end(i);
        out.positions.insert(out.positions.end(), strands.positions.begin() + b,
                             strands.positions.begin() + e);
        out.offsets.push_back(static_cast<std::uint32_t>(out.positions.size()));
        if (hasT) out.thickness.insert(out.thickness.end(), strands.thickness.begin() + b, strands.thickness.begin() + e);
        if (hasA) out.transparency.insert(out.transparency.end(), strands.transparency.begin() + b, strands.transparency.begin() + e);
        if (hasC) out.color.insert(out.color.end(), strands.color.begin() + b, strands.color.begin() + e);
        if (hasUV) out.rootUV.push_back(strands.rootUV[i]);
        if (hasId) out.strandId.push_back(strands.strandId[i]);
    }
    return out;
}

void scaleStrands(StrandSet& strands, float factor)
{
    for (Vec3f& p : strands.positions) p *= factor;
    const float a = std::abs(factor);
    for (float& t : strands.thickness) t *= a;
    strands.defaults.thickness *= a;
}

double metersPerUnitFromName(const std::string& text, const std::string& what)
{
    if (text == "mm") return 0.001;
    if (text == "cm") return 0.01;
    if (text == "dm") return 0.1;
    if (text == "m") return 1.0;
    if (text == "in") return 0.0254;
    char* end = nullptr;
    const double v = std::strtod(text.c_str(), &end);
    if (text.empty() || *end != '\0' || !(v > 0.0) || !std::isfinite(v)) {
        throw ValueError(what + " '" + text + "': expected mm, cm, dm, m, in or the unit's length in metres (0.01 for centimetres)");
    }
    return v;
}

void convertUnits(StrandSet& strands, double metersPerUnit)
{
    if (!(metersPerUnit > 0.0) || !std::isfinite(metersPerUnit)) {
        throw ValueError("convertUnits: metersPerUnit " + std::to_string(metersPerUnit) + " must be a positive length in metres");
    }
    if (!(strands.metersPerUnit > 0.0)) {
        throw ValueError("convertUnits: the strands declare no unit, so there is nothing to convert from; give their unit first "
                         "(StrandSet::metersPerUnit)");
    }
    const double factor = strands.metersPerUnit / metersPerUnit;
    if (factor != 1.0) scaleStrands(strands, float(factor));
    strands.metersPerUnit = metersPerUnit;
}

} // namespace vdbhair
