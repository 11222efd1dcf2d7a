/// @file HeadOptions.h
/// @brief The head option pair that refine, demo and comb share: `--head FILE|none` and
/// `--head-policy no-deeper|outside` (vdbhair/field/HeadObstacle.h).
#pragma once

#include <vdbhair/field/HeadObstacle.h>

#include <CLI/CLI.hpp>

#include <string>

namespace vdbhair::app {

struct HeadOptions
{
    std::string path;                   ///< --head: a mesh, a .vdb level set, or "none"
    std::string policy = headPolicyName(kDefaultHeadPolicy);  ///< --head-policy
    /// @throw ValueError naming --head-policy for a policy that is not one of no-deeper, outside.
    HeadPolicy headPolicy() const;
};

/// @param fallback what the head is without --head, for the help text ("--scalp's sphere if given,
/// else a sphere fitted to the roots")
void addHeadOptions(CLI::App* sub, HeadOptions& o, const std::string& fallback);

/// @brief HeadObstacle::none() for `--head none`, the file's head for a path, else @a fallback.
/// @throw IoError, FormatError, LookupError (unreadable --head), ValueError (bad policy).
HeadObstacle headFromOptions(const HeadOptions& o, const HeadObstacle& fallback = HeadObstacle());

} // namespace vdbhair::app
