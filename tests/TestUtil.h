/// @file TestUtil.h
/// @brief Shared helpers for the Catch2 tests: analytic curves, temporary files, the shared data.
#pragma once

#include <vdbhair/Types.h>
#include <vdbhair/strands/StrandSet.h>

#include <catch2/catch.hpp>

#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <iostream>
#include <string>
#include <vector>

#include <unistd.h>

namespace vdbhair::test {

/// Points of a helix of radius r and pitch parameter c ((r cos t, r sin t, c t)),
/// t in [tMin, tMin + tSpan].
inline std::vector<Vec3f> helix(double r, double c, double tSpan, std::size_t n, double tMin = 0.0)
{
    std::vector<Vec3f> p(n);
    for (std::size_t i = 0; i < n; ++i) {
        const double t = tMin + tSpan * double(i) / double(n - 1);
        p[i] = Vec3f(float(r * std::cos(t)), float(r * std::sin(t)), float(c * t));
    }
    return p;
}

/// Points of a circle of radius r in the xy plane centred at the origin, over angle [0, aMax].
inline std::vector<Vec3f> circleArc(double r, double aMax, std::size_t n)
{
    return helix(r, 0.0, aMax, n);
}

/// A folder for this test run's files, removed at the end of the process.
inline const std::filesystem::path& tempDir()
{
    static struct Dir {
        std::filesystem::path path;
        Dir()
        {
            path = std::filesystem::temp_directory_path() /
                   ("vdbhair-test-" + std::to_string(::getpid()));
            std::filesystem::create_directories(path);
        }
        ~Dir() { std::error_code ec; std::filesystem::remove_all(path, ec); }
    } dir;
    return dir.path;
}

inline std::string tempPath(const std::string& name) { return (tempDir() / name).string(); }

/// A committed input of tests/io/data (the fuzzers' findings, issue 22), checked to be there.
inline std::string regressionInput(const std::string& name)
{
    const std::filesystem::path path = std::filesystem::path(VDBHAIR_TEST_INPUTS_DIR) / name;
    REQUIRE(std::filesystem::is_regular_file(path));
    return path.string();
}

/// Write raw bytes to a file in the temporary folder and return its path.
inline std::string writeBytes(const std::string& name, const std::string& bytes)
{
    const std::string path = tempPath(name);
    std::ofstream(path, std::ios::binary).write(bytes.data(), std::streamsize(bytes.size()));
    return path;
}

inline std::string readBytes(const std::string& path)
{
    std::ifstream in(path, std::ios::binary);
    return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

/// Append the bytes of a plain value (little-endian, as the machine is).
template<typename T>
void put(std::string& s, const T& v)
{
    s.append(reinterpret_cast<const char*>(&v), sizeof(T));
}

/// The shared real-data folder (../shared/data next to the checkout), or "" when absent.
/// VDBHAIR_SHARED_DATA in the environment overrides the location.
inline std::string sharedData()
{
    if (const char* env = std::getenv("VDBHAIR_SHARED_DATA")) return env;
#ifdef VDBHAIR_SHARED_DATA_DIR
    if (std::filesystem::is_directory(VDBHAIR_SHARED_DATA_DIR)) return VDBHAIR_SHARED_DATA_DIR;
#endif
    return "";
}

/// A few strands with every attribute, for round trips.
inline StrandSet sampleStrands(bool attributes = true)
{
    StrandSet s;
    s.addStrand(helix(1.0, 0.3, 6.0, 17));
    s.addStrand(std::vector<Vec3f>{Vec3f(0.f), Vec3f(1.f, 0.f, 0.f)});
    s.addStrand(circleArc(2.0, 3.0, 33));
    for (Vec3f& p : s.positions) p += Vec3f(0.125f, -3.5f, 10.f);
    if (attributes) {
        for (std::size_t v = 0; v < s.numVertices(); ++v) {
            s.thickness.push_back(0.01f * float(v + 1));
            s.transparency.push_back(float(v % 5) / 8.f);
            s.color.emplace_back(float(v % 7) / 7.f, float(v % 3) / 3.f, 0.25f);
        }
    }
    return s;
}

/// Same topology and positions within @a tol (absolute, world units).
inline void requireSameStrands(const StrandSet& a, const StrandSet& b, float tol = 0.f)
{
    REQUIRE(a.numStrands() == b.numStrands());
    REQUIRE(a.offsets == b.offsets);
    float worst = 0.f;
    std::size_t worstAt = 0;
    for (std::size_t v = 0; v < a.numVertices(); ++v) {
        const float d = (a.positions[v] - b.positions[v]).length();
        if (d > worst) { worst = d; worstAt = v; }
    }
    CAPTURE(worstAt, tol);
    REQUIRE(worst <= tol);
}

#ifdef VDBHAIR_SOURCE_DIR
/// docs/cli.md, whose option tables are generated from the parameters' declarations.
inline std::string cliPage()
{
    std::ifstream in(std::string(VDBHAIR_SOURCE_DIR) + "/docs/cli.md");
    REQUIRE(in);
    std::stringstream page;
    page << in.rdbuf();
    return page.str();
}
#endif

} // namespace vdbhair::test

/// Skip the rest of a test case, saying so, when the shared real data is not available. Such a
/// case must be tagged [data]: those run as one CTest ("unit: real data"), which ctest reports as
/// skipped when the output says SKIPPED (tests/CMakeLists.txt).
#define VDBHAIR_REQUIRE_SHARED_DATA()                                                          \
    do {                                                                                       \
        if (vdbhair::test::sharedData().empty()) {                                             \
            std::cout << "SKIPPED: the shared real data (../shared/data) is not available\n";  \
            WARN("SKIPPED: the shared real data (../shared/data) is not available");           \
            return;                                                                            \
        }                                                                                      \
    } while (0)
