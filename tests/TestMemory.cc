#include <vdbhair/Exceptions.h>
#include <vdbhair/Memory.h>

#include <catch2/catch.hpp>

#include <new>
#include <thread>
#include <vector>

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

TEST_CASE("AllocationBudget: the calling thread's live bytes stay within it, and a request past it throws before allocating", "[core]")
{
    constexpr std::uint64_t kMiB = std::uint64_t(1) << 20;
    AllocationBudget budget(kMiB);
    CHECK(AllocationBudget::current() == &budget);
    {
        std::vector<char> a(kMiB / 2), kept;
        CHECK(budget.live() >= kMiB / 2);
        try {
            std::vector<char> b(kMiB * 6 / 10);
            FAIL("a request past the budget was met");
        } catch (const BudgetExceeded& e) {
            CHECK(e.requested() == kMiB * 6 / 10);
            CHECK(e.limit() == kMiB);
            CHECK(e.live() >= kMiB / 2);
            CHECK_THAT(e.what(), Contains("would pass the budget of 1048576 bytes"));
        }
        CHECK(new (std::nothrow) char[kMiB] == nullptr);  // nothrow new: null, as when memory runs out
        std::thread other([] { std::vector<char> big(8 * kMiB, 1); CHECK(big[kMiB] == 1); });  // other threads: not counted
        other.join();
        {
            AllocationBudget inner(16 * kMiB);  // held to what the outer has left
            CHECK(inner.limit() <= kMiB / 2);
            CHECK_THROWS_AS(std::vector<char>(kMiB * 6 / 10), BudgetExceeded);
            kept.resize(kMiB / 4);  // outlives the inner budget: counts in the outer one when it ends
        }
        CHECK(budget.live() >= kMiB * 3 / 4);
    }
    CHECK(budget.live() < kMiB / 8);  // every block freed
    CHECK(budget.peak() >= kMiB * 3 / 4);
    std::vector<char> d(kMiB * 6 / 10);  // room again
    CHECK(d.size() == kMiB * 6 / 10);
}

TEST_CASE("AllocationBudget: gone with its scope", "[core]")
{
    { AllocationBudget budget(1024); }
    CHECK(AllocationBudget::current() == nullptr);
    std::vector<char> big(std::size_t(64) << 20);
    CHECK(big.size() == std::size_t(64) << 20);
}
