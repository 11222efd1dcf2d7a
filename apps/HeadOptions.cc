#include "HeadOptions.h"

#include <vdbhair/Exceptions.h>

namespace vdbhair::app {

void addHeadOptions(CLI::App* sub, HeadOptions& o, const std::string& fallback)
{
    sub->add_option("--head", o.path, "The head strands may not enter: a triangle mesh (.ply, .obj), a .vdb with a level set grid "
                                      "('surface' or the first one), or 'none' (default: " + fallback + ")");
    sub->add_option("--head-policy", o.policy, "no-deeper: no vertex enters the head that the input had outside it, "
                                               "hair already inside is left as it was; outside: every vertex is moved out")->capture_default_str();
}

HeadPolicy HeadOptions::headPolicy() const
{
    try {
        return headPolicyFromName(policy);
    } catch (const ValueError&) {
        throw ValueError("--head-policy " + policy + ": must be no-deeper or outside");
    }
}

HeadObstacle headFromOptions(const HeadOptions& o, const HeadObstacle& fallback)
{
    const HeadPolicy policy = o.headPolicy();
    if (o.path == "none") return HeadObstacle::none();
    if (!o.path.empty()) return readHeadObstacle(o.path, "--head " + o.path, policy);
    return fallback;
}

} // namespace vdbhair::app
