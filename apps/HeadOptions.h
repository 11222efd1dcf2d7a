/// @file HeadOptions.h
/// @brief The head option that refine, demo and comb share: `--head FILE|none`, made with the
/// verb's declared head policy (`--head-policy`, headPolicyParam(), vdbhair/field/HeadObstacle.h).
#pragma once

#include <vdbhair/field/HeadObstacle.h>
#include <vdbhair/io/RootEnd.h>

#include <CLI/CLI.hpp>

#include <string>

namespace vdbhair::app {

struct HeadOptions
{
    std::string path;  ///< --head: a mesh, a .vdb level set, or "none"
    /// The verb's declared head policy (RefineParams::headPolicy, CombParams::headPolicy); null:
    /// kDefaultHeadPolicy (synth and transfer, which take none)
    const HeadPolicy* policy = nullptr;
    HeadPolicy headPolicy() const { return policy ? *policy : kDefaultHeadPolicy; }
};

/// @brief `--head` into @a o, whose heads are made with the policy @a policy (the verb's declared
/// head policy, which must outlive parsing).
/// @param fallback what the head is without --head, for the help text ("--scalp's sphere if given,
/// else a sphere fitted to the roots")
void addHeadOptions(CLI::App* sub, HeadOptions& o, const HeadPolicy& policy, const std::string& fallback);

/// @brief HeadObstacle::none() for `--head none`, the file's head for a path, else @a fallback.
/// @throw IoError, FormatError, LookupError (unreadable --head).
HeadObstacle headFromOptions(const HeadOptions& o, const HeadObstacle& fallback = HeadObstacle());

/// @brief Unsigned distance to the head in @a path, for `--roots auto --head` (ReadOptions::rootsHeadDistance):
/// for a mesh (.ply, .obj) the distance to its nearest vertex (a k-d tree; the shared heads have
/// 3,000 to 44,000 vertices, closer together than a root is to a tip), for a .vdb the level set's
/// |distance| (within its band; its background beyond).
/// @throw what readTriangleMesh() and readHeadObstacle() throw.
SurfaceDistanceFn headSurfaceDistance(const std::string& path);

} // namespace vdbhair::app
