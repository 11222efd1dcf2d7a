/// @file ReadOptions.h
/// @brief What every strand reader accepts and reports.
#pragma once

#include <vdbhair/Exceptions.h>
#include <vdbhair/Parameters.h>
#include <vdbhair/io/RootEnd.h>
#include <vdbhair/Types.h>
#include <vdbhair/strands/StrandSet.h>

#include <openvdb/util/NullInterrupter.h>

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace vdbhair {

/// @brief What a reader does with a strand of fewer than two vertices (a polyline needs two).
///
/// The default is Drop: such strands carry no direction, and real data has them (scalp samples
/// without hair in the USC-HairSalon database, empty slots in HairNet's grids), so they are
/// skipped, counted and reported as a warning. Reject makes them an error instead.
enum class ShortStrandPolicy { Drop, Reject };

struct ReadOptions
{
    ShortStrandPolicy shortStrands = ShortStrandPolicy::Drop;
    /// Optional progress and Ctrl-C while the file's bytes are read (Progress.h); readers then
    /// throw InterruptedError when it says stop.
    openvdb::util::NullInterrupter* interrupter = nullptr;
    /// `.vdb`: the name of the points grid that holds the strands (Houdini and the demo's
    /// `strands_input` use other names than the default).
    std::string vdbGrid = "strands";
    /// `.obj` and `.ply` edges: edges carry no direction, so each strand rebuilt from them is rooted at the end
    /// nearest this point (e.g. the scalp's centre) when it is set, otherwise at its end with the
    /// lower vertex index (which is the root of every file vdbhair and Blender write).
    /// (PLY edge line sets too.)
    std::optional<Vec3f> objRootNear;
    /// `.ply` without strand topology (only a `vertex` element, as NeuralHaircut and GaussianHaircut
    /// write): each run of this many consecutive vertices is one strand (they write 100). 0: not
    /// set, and such a file is an error that says to set it. Ignored when the file has topology.
    std::size_t pointsPerStrand = 0;
    /// `.obj` free-form curves (`curv`) and cubic USD and Alembic curves: the points each curve is evaluated at, evenly in its
    /// parameter. 0: chosen per curve so that the polyline keeps the curve's shape within 1 % of
    /// its length (FreeFormCurve.h explains the rule).
    std::size_t curveSamples = 0;
    /// Which end of each strand is its root (RootEnd.h): First (the default), Last (every strand
    /// reversed), or Auto (measured on the file). Applied by readStrands() after any reader.
    RootEnd roots = RootEnd::First;
    /// For RootEnd::Auto: unsigned distance to the head's surface (the end nearer it is the root);
    /// empty: the rule without a head.
    SurfaceDistanceFn rootsHeadDistance;
    /// How the readers' warnings name the options above (their errors are ParamErrors): Python's
    /// read() keywords, or the command line's flags.
    ParamSpelling spelling = ParamSpelling::Keyword;
    /// The name of @c roots: the command line's --roots, or --root-end where a verb's --roots
    /// names something else (interpolate's root positions).
    ParamName rootsName{"--roots", "roots"};
};

/// @brief The readers' options a person sets, declared once (vdbhair/Parameters.h): strict, grid,
/// points-per-strand, curve-samples and roots. The command line's reading options
/// (apps/Cli.cc addReadOptions(), addStrictOption(); `convert` and `render` take `--grid`) and
/// Python's read() keywords are made from it. root_near stays each front end's own (an optional
/// point is not a declared type).
const ParamTable<ReadOptions>& readParameters();

/// @brief Check the declared options of @a opts (readParameters()) and what their ranges cannot
/// say: a curve of one sample. readStrands() calls it; errors name the options in @a opts.spelling.
/// @throw ParamError<ValueError> "curve_samples 1: must be 0 (automatic) or 2 or more".
void checkReadOptions(const ReadOptions& opts);

/// The readers' options as messages name them (readParameters(); @c roots: ReadOptions::rootsName).
inline ParamName readParamName(const std::string& name)
{
    return paramName(readParameters(), name);
}

/// @brief An option set to a value, as each front end shows it: "--points-per-strand 100" on the
/// command line, "points_per_strand=100" in Python (the name and what stands before the value).
inline ParamName readOptionSetting(const ParamName& option)
{
    return {option.flag + " ", option.keyword + "="};
}

/// @brief What a reader noticed but did not fail on.
struct ReadReport
{
    std::size_t droppedStrands = 0;     ///< strands of fewer than two vertices, skipped
    std::vector<std::string> warnings;  ///< one line each, prefixed with the reader and file
};

/// @brief Applies the short-strand policy and counts what it drops (shared by every reader).
class ShortStrandFilter
{
public:
    ShortStrandFilter(const ReadOptions& opts, ReadReport* report, std::string where)
        : mOpts(opts), mReport(report), mWhere(std::move(where)) {}

    /// @brief Whether strand @a index of @a vertexCount vertices is kept.
    /// @param location "at byte 1234" or "line 17", for the message
    /// @throw FormatError under ShortStrandPolicy::Reject.
    bool keep(std::size_t index, std::size_t vertexCount, const std::string& location)
    {
        if (vertexCount >= 2) return true;
        if (mOpts.shortStrands == ShortStrandPolicy::Reject) {
            throw FormatError(mWhere + ": " + location + ": strand " + std::to_string(index) +
                              " has " + std::to_string(vertexCount) +
                              " vertices; a strand needs at least 2");
        }
        if (mDropped++ == 0) mFirst = index;
        return false;
    }

    /// @brief Record the warning for what was dropped.
    void finish()
    {
        if (mDropped == 0 || !mReport) return;
        mReport->droppedStrands += mDropped;
        mReport->warnings.push_back(mWhere + ": dropped " + std::to_string(mDropped) +
                                    " strand(s) with fewer than 2 vertices (first: strand " +
                                    std::to_string(mFirst) + ")");
    }

private:
    const ReadOptions& mOpts;
    ReadReport* mReport;
    std::string mWhere;
    std::size_t mDropped = 0, mFirst = 0;
};

/// @brief What reader loops call once per item so that SIGTERM and Ctrl-C end them: every 4096
/// calls it asks the interrupter (ReadOptions::interrupter, may be null) and throws
/// InterruptedError when it says stop. Cheap enough for the innermost loop of a reader.
class InterruptPoll
{
public:
    InterruptPoll(openvdb::util::NullInterrupter* interrupter, std::string where)
        : mInterrupter(interrupter), mWhere(std::move(where)) {}

    /// @throw InterruptedError when the interrupter says stop.
    void operator()()
    {
        if (!mInterrupter || (++mCalls & 4095u) != 0) return;
        if (mInterrupter->wasInterrupted()) throw InterruptedError(mWhere + ": interrupted while reading");
    }

private:
    openvdb::util::NullInterrupter* mInterrupter;
    std::string mWhere;
    std::uint32_t mCalls = 0;
};

/// @brief Throw unless @a p is finite.
inline void checkFinite(const Vec3f& p, std::size_t vertex, const std::string& where,
                        const std::string& location)
{
    if (std::isfinite(p.x()) && std::isfinite(p.y()) && std::isfinite(p.z())) return;
    throw FormatError(where + ": " + location + ": vertex " + std::to_string(vertex) +
                      " has a non-finite coordinate (" + std::to_string(p.x()) + ", " +
                      std::to_string(p.y()) + ", " + std::to_string(p.z()) +
                      "); coordinates must be finite");
}

} // namespace vdbhair
