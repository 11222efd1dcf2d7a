/// @file Scene.h
/// @brief Helicoid scene files (`scene/1` JSON) and growing them into strands.
///
/// ```json
/// {"vdbhair": "scene/1", "seed": 7, "step": 0.01, "head": {"sphere": [0, 0, 0, 10]},
///  "guides": [
///   {"root": [0,0,0], "frame": {"tangent": [1,0,0], "normal": [0,1,0]},
///    "pieces": [{"k": [1.0, -0.1, 0.3, 1.0], "length": 2.0, "roll": 0.0}],
///    "waviness": {"amplitude": 0.02, "frequency": 40.0, "phase": 0.0, "noise": 0.0},
///    "wisp": {"count": 256, "radius": 0.05, "fanning": 0.0, "normal": [0,1,0], "strays": 0.05},
///    "fit": {...}}]}
/// ```
/// `step` is the tracing step in world units and `integrator` (optional) "euler" (Eq. 3, the
/// default) or "rk4" (which `vdbhair fit` writes: fits are exact streamlines); a guide may override it with its own
/// `step` (`vdbhair fit` writes one per guide, fitted at its strand's scale). `roll`, `waviness`
/// (and its `phase` and `noise`), `wisp`, `fit` and a guide's `step` are optional; `fit` (written by `vdbhair fit`) is kept but ignored
/// by growing. A wisp's `normal` (optional) is the scalp's normal at the guide's root: its roots are
/// then sampled in the scalp's tangent plane instead of perpendicular to the guide (WispParams); its
/// `strays` (optional, a fraction in [0, 1], default 0) makes that share of its strands strays,
/// rotated by 0.3-0.6 rad out of the wisp's flow. The scene-level `head` (optional) names the head
/// the hair grows on, `{"sphere": [cx, cy, cz, r]}`: growing ignores it; `render` draws it (see
/// makeSphereMesh()). Unknown keys and malformed values are errors that name the key path:
/// `scene.json: guides[3].pieces[0].k: expected 4 numbers`.
#pragma once

#include <vdbhair/Parameters.h>
#include <vdbhair/helicoid/Helicoid.h>
#include <vdbhair/helicoid/Waviness.h>
#include <vdbhair/helicoid/Wisp.h>
#include <vdbhair/strands/StrandSet.h>

#include <nlohmann/json.hpp>
#include <openvdb/util/NullInterrupter.h>

#include <cstdint>
#include <limits>
#include <optional>
#include <string>
#include <vector>

namespace vdbhair {

struct SceneGuide
{
    Vec3d root{0.0};
    FrameD frame;
    std::vector<HelicoidPiece> pieces;
    std::optional<WavinessParams> waviness;
    std::optional<WispParams> wisp;
    nlohmann::json fit;  ///< null when absent; kept as written
    double step = 0.0;   ///< this guide's tracing step; 0: the scene's (optional key "step", written by fit)
};

/// @brief The head a scene's hair grows on (optional key "head"): today a sphere.
struct SceneHead
{
    Vec3d center{0.0};  ///< world units
    double radius = 0.0;  ///< world units, positive
};

struct Scene
{
    std::uint64_t seed = 0;
    double step = 0.01;
    HelicoidIntegrator integrator = HelicoidIntegrator::Euler;  ///< optional key "integrator": "euler" (Eq. 3) or "rk4"
    std::vector<SceneGuide> guides;
    std::optional<SceneHead> head;  ///< optional key "head": {"sphere": [cx, cy, cz, r]}
};

/// @brief Parse a scene from JSON. @param where message prefix (the file name).
/// @throw FormatError naming the key path and the rule.
Scene sceneFromJson(const nlohmann::json& j, const std::string& where);
nlohmann::json sceneToJson(const Scene& scene);

/// How deep a scene file may nest arrays and objects (a scene needs 5; `fit` records a few more).
/// Deeper documents are refused by key path before a json value is built, because building,
/// copying and destroying one recurses on its depth (200,000 levels overflowed the stack).
constexpr std::size_t kMaxSceneDepth = 64;

/// @throw IoError, FormatError (also for invalid JSON, with its line and column; for nesting
/// beyond kMaxSceneDepth and numbers beyond a double, with the key path).
Scene readScene(const std::string& path);
/// @brief Write atomically, one guide per line.
void writeScene(const std::string& path, const Scene& scene);

struct GrowOptions
{
    std::optional<HelicoidIntegrator> integrator;  ///< overrides the scene's
    std::size_t maxVertices = std::size_t(1) << 30;  ///< refuse scenes that would grow more
    /// A guide whose trace comes within this many steps of a piece's singular axis is reported
    /// (GrowReport). One step, not the fitter's kAxisClearanceSteps margin: between 1 and 2 steps
    /// RK4 traces at h and h/16 still agree to about 1e-4 of their length (seeded pieces, kN < 0),
    /// and every strand issue 19 found changing with the step had passed within one step of the axis.
    double nearAxisSteps = 1.0;
};

/// @brief grow's declared parameters (vdbhair/Parameters.h): the integrator ("scene": the
/// scene's own) and the vertex cap.
const ParamTable<GrowOptions>& growParameters();

/// @brief What growScene() found while tracing: guides whose trace is not a converged
/// streamline because it passes within GrowOptions::nearAxisSteps of a piece's singular axis,
/// where the strand changes with the step (issue 19).
struct GrowReport
{
    std::size_t nearAxis = 0;       ///< guides whose trace comes nearer than GrowOptions::nearAxisSteps
    std::size_t nearestGuide = 0;   ///< the guide that comes nearest
    double nearestClearance = std::numeric_limits<double>::infinity();  ///< its distance, in steps (traceClearance)
};

/// @brief Strands of a scene: each guide, then its wisp strands. Bitwise identical for any
/// thread count (each strand's randomness comes from (seed, guide, strand)).
/// @param interrupter optional progress and Ctrl-C (Progress.h).
/// @param[out] report optional: guides whose trace does not converge (checked on every guide's trace).
/// @throw LimitError if the scene would exceed options.maxVertices vertices; InterruptedError
/// when the interrupter stops the work.
StrandSet growScene(const Scene& scene, const GrowOptions& options = {}, bool threaded = true,
                    openvdb::util::NullInterrupter* interrupter = nullptr, GrowReport* report = nullptr);

/// @brief The guides of @a scene alone, one strand each, without their wisps (what point
/// interpolation blends when its guides come as a scene).
/// @throw as growScene().
StrandSet growGuides(const Scene& scene, bool threaded = true, openvdb::util::NullInterrupter* interrupter = nullptr);

/// @brief The vertex count growScene() would produce (checked against overflow).
std::size_t sceneVertexCount(const Scene& scene);

} // namespace vdbhair
