#include <vdbhair/Exceptions.h>
#include <vdbhair/Memory.h>

#include <catch2/catch.hpp>

using namespace vdbhair;
using Catch::Matchers::Contains;

TEST_CASE("checkMemory: a request over the memory it may use is refused naming what and how much", "[core]")
{
    CHECK(formatBytes(900) == "900 B");
    CHECK(formatBytes(3 * 1024) == "3 KiB");
    CHECK(formatBytes(std::uint64_t(512) << 20) == "512 MiB");
    CHECK(formatBytes((std::uint64_t(11) << 30) + (std::uint64_t(1) << 29)) == "11.50 GiB");
    CHECK(availableMemoryBytes(12345) == 12345);
    CHECK(availableMemoryBytes() > (std::uint64_t(16) << 20));  // MemAvailable, or no limit
    CHECK_NOTHROW(checkMemory("resample", 1000, "1000 bytes", "fewer", 1000));
    REQUIRE_THROWS_AS(checkMemory("resample", std::uint64_t(12) << 30, "1e9 vertices of 12 bytes", "fewer vertices", std::uint64_t(10) << 30), LimitError);
    REQUIRE_THROWS_WITH(checkMemory("resample", std::uint64_t(12) << 30, "1e9 vertices of 12 bytes", "fewer vertices", std::uint64_t(10) << 30),
                        "resample: needs about 12.00 GiB (1e9 vertices of 12 bytes), more than the 10.00 GiB of maxMemory; fewer vertices");
}
