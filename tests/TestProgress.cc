#include "TestUtil.h"

#include <vdbhair/Exceptions.h>
#include <vdbhair/Progress.h>
#include <vdbhair/field/StreamlineTracer.h>
#include <vdbhair/field/TangentField.h>
#include <vdbhair/helicoid/HelicoidField.h>
#include <vdbhair/helicoid/HelicoidFit.h>
#include <vdbhair/helicoid/Scene.h>
#include <vdbhair/io/FileUtil.h>
#include <vdbhair/io/MappedFile.h>
#include <vdbhair/io/StrandIO.h>
#include <vdbhair/render/StrandRenderer.h>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <map>
#include <mutex>

using namespace vdbhair;

namespace {

/// Records what the library reports; says stop once @a stopAt items of a stage are done (never for 0).
class Recorder : public WorkInterrupter
{
public:
    struct Stage
    {
        std::uint64_t total = 0, done = 0;
        std::string unit;
        int maxPercent = -1;
        bool ended = false;
    };
    explicit Recorder(std::uint64_t stopAt = 0) : mStopAt(stopAt) {}

    void startWork(const char* name, std::uint64_t total, const char* unit) override
    {
        std::lock_guard<std::mutex> lock(mMutex);
        mCurrent = name;
        order.push_back(name);
        stages[name] = Stage{total, 0, unit, -1, false};
    }
    void end() override
    {
        std::lock_guard<std::mutex> lock(mMutex);
        stages[mCurrent].ended = true;
    }
    bool wasInterruptedAt(std::uint64_t done, int percent) override
    {
        std::lock_guard<std::mutex> lock(mMutex);
        Stage& s = stages[mCurrent];
        s.done = std::max(s.done, done);
        s.maxPercent = std::max(s.maxPercent, percent);
        ++reports;
        return mStopAt > 0 && done >= mStopAt;
    }
    bool wasInterrupted(int percent) override { return wasInterruptedAt(0, percent); }

    std::map<std::string, Stage> stages;
    std::vector<std::string> order;
    std::size_t reports = 0;

private:
    std::mutex mMutex;
    std::string mCurrent;
    std::uint64_t mStopAt;
};

/// A plain OpenVDB interrupter (no WorkInterrupter): sees only percentages.
class PercentOnly : public openvdb::util::NullInterrupter
{
public:
    bool wasInterrupted(int percent) override
    {
        std::lock_guard<std::mutex> lock(mMutex);
        maxPercent = std::max(maxPercent, percent);
        return false;
    }
    void start(const char*) override { ++starts; }
    void end() override { ++ends; }
    int maxPercent = -1, starts = 0, ends = 0;

private:
    std::mutex mMutex;
};

/// Many wavy strands (enough for several blocks of every parallel loop).
StrandSet manyStrands(int side)
{
    StrandSet s;
    for (int i = 0; i < side; ++i) {
        for (int j = 0; j < side; ++j) {
            std::vector<Vec3f> pts;
            for (int k = 0; k < 12; ++k) {
                pts.emplace_back(0.1f * float(i) + 0.05f * std::sin(0.7f * float(k) + float(j)), 0.1f * float(j), 0.2f * float(k));
            }
            s.addStrand(pts);
        }
    }
    return s;
}

} // namespace

TEST_CASE("ProgressCounter: items added from many threads reach the total, 100 %, and end the stage", "[progress]")
{
    Recorder rec;
    {
        ProgressCounter counter(&rec, "counting", 100000, "items");
        tbb::parallel_for(tbb::blocked_range<int>(0, 100000, 64), [&](const tbb::blocked_range<int>& r) {
            for (int i = r.begin(); i != r.end(); ++i) counter.add(1);
        });
        CHECK_FALSE(counter.stopped());
    }
    const Recorder::Stage& s = rec.stages.at("counting");
    CHECK(s.total == 100000);
    CHECK(s.unit == "items");
    CHECK(s.done == 100000);
    CHECK(s.maxPercent == 100);
    CHECK(s.ended);

    // A plain OpenVDB interrupter gets start, percentages and end.
    PercentOnly plain;
    {
        ProgressCounter counter(&plain, "counting", 10, "items");
        for (int i = 0; i < 10; ++i) counter.add(1);
    }
    CHECK(plain.starts == 1);
    CHECK(plain.ends == 1);
    CHECK(plain.maxPercent == 100);

    // Without an interrupter nothing is reported and nothing stops.
    ProgressCounter none(nullptr, "counting", 10, "items");
    CHECK_FALSE(none.add(10));
    CHECK_FALSE(none.interrupted());
}

TEST_CASE("ProgressCounter: a stop is remembered and seen by every thread", "[progress]")
{
    Recorder rec(500);
    ProgressCounter counter(&rec, "counting", 1000, "items");
    std::atomic<int> after{0};
    tbb::parallel_for(tbb::blocked_range<int>(0, 1000, 1), [&](const tbb::blocked_range<int>& r) {
        for (int i = r.begin(); i != r.end(); ++i) {
            if (counter.stopped()) return;
            counter.add(1);
            ++after;
        }
    });
    CHECK(counter.stopped());
    CHECK(after.load() < 1000);
}

TEST_CASE("Progress: estimation and retracing report every strand and give the same grids and strands", "[progress]")
{
    const StrandSet s = manyStrands(48);  // 2304 strands
    FieldParams fp;
    fp.voxelSize = 0.1;
    Recorder rec;
    const TangentField with = estimateTangentField(s, fp, true, &rec);
    const TangentField without = estimateTangentField(s, fp);
    REQUIRE(rec.stages.count("estimating the tangent field"));
    const Recorder::Stage& est = rec.stages.at("estimating the tangent field");
    CHECK(est.total == s.numStrands());
    CHECK(est.done == s.numStrands());
    CHECK(est.ended);
    const Recorder::Stage& dirs = rec.stages.at("estimating the tangent field: robust directions (Eq. 9)");
    CHECK(dirs.total == with.tangent->tree().leafCount());
    CHECK(dirs.done == dirs.total);
    REQUIRE(with.tangent->activeVoxelCount() == without.tangent->activeVoxelCount());
    auto acc = without.tangent->getConstAccessor();
    std::size_t differ = 0;
    for (auto it = with.tangent->cbeginValueOn(); it; ++it) differ += acc.getValue(it.getCoord()) != *it;
    CHECK(differ == 0);

    TraceParams tp;
    const StrandSet a = retraceStrands(s, *with.tangent, tp, nullptr, nullptr, true, &rec);
    const StrandSet b = retraceStrands(s, *with.tangent, tp);
    const Recorder::Stage& tr = rec.stages.at("tracing streamlines");
    CHECK(tr.done == s.numStrands());
    CHECK(tr.ended);
    CHECK(a.positions == b.positions);
    CHECK(a.offsets == b.offsets);
}

TEST_CASE("Progress: every long operation stops with InterruptedError when told to", "[progress]")
{
    const StrandSet s = manyStrands(48);
    FieldParams fp;
    fp.voxelSize = 0.1;
    const TangentField field = estimateTangentField(s, fp);

    SECTION("estimateTangentField")
    {
        Recorder rec(1);
        CHECK_THROWS_AS(estimateTangentField(s, fp, true, &rec), InterruptedError);
        CHECK(rec.stages.begin()->second.ended);
    }
    SECTION("estimateTangentFieldLevels")
    {
        Recorder rec(1);
        CHECK_THROWS_AS(estimateTangentFieldLevels(s, fp, 2, true, &rec), InterruptedError);
        CHECK(rec.order.front() == "estimating level 0 of 2");
    }
    SECTION("retraceStrands, one and two threads")
    {
        for (bool threaded : {false, true}) {
            Recorder rec(1);
            CHECK_THROWS_AS(retraceStrands(s, *field.tangent, TraceParams(), nullptr, nullptr, threaded, &rec), InterruptedError);
        }
    }
    SECTION("estimateHelicoidField and retraceHelicoidField")
    {
        Recorder rec(1);
        CHECK_THROWS_AS(estimateHelicoidField(*field.tangent, true, &rec), InterruptedError);
        const HelicoidFieldGrids h = estimateHelicoidField(*field.tangent);
        Recorder rec2(1);
        CHECK_THROWS_AS(retraceHelicoidField(s, h, TraceParams(), nullptr, true, &rec2), InterruptedError);
    }
    SECTION("fitStrands")
    {
        StrandSet few;
        for (std::size_t i = 0; i < 40; ++i) few.addStrand(s.data(i), s.size(i));
        Recorder rec(1);
        CHECK_THROWS_AS(fitStrands(few, FitParams(), true, nullptr, &rec), InterruptedError);
        CHECK(rec.stages.at("fitting p-helicoids").done < few.numStrands());
    }
    SECTION("growScene")
    {
        Scene scene;
        scene.step = 0.01;
        for (int g = 0; g < 64; ++g) {
            SceneGuide guide;
            guide.root = Vec3d(double(g), 0.0, 0.0);
            guide.pieces.push_back(HelicoidPiece{HelicoidParams{1.0, 0.2, 0.1, 0.5}, 1.0, 0.0});
            scene.guides.push_back(guide);
        }
        Recorder rec(1);
        CHECK_THROWS_AS(growScene(scene, {}, true, &rec), InterruptedError);
        Recorder counting;
        const StrandSet grown = growScene(scene, {}, true, &counting);
        CHECK(grown.numStrands() == 64);
        CHECK(counting.stages.at("growing strands").done == 128);  // 64 guides traced, 64 strands grown
    }
    SECTION("renderStrands")
    {
        RenderParams rp;
        rp.width = rp.height = 64;
        Recorder rec(1);
        rp.interrupter = &rec;
        CHECK_THROWS_AS(renderStrands(s, rp), InterruptedError);
    }
}

TEST_CASE("Progress: reading a file reports its bytes and stops when told to", "[progress]")
{
    // 20 MiB: three pieces of the reader's 8 MiB.
    const std::string path = test::writeBytes("progress.bin", std::string(20u << 20, 'x'));
    Recorder rec;
    const std::vector<char> bytes = readFileBytes(path, "test", &rec);
    CHECK(bytes.size() == (20u << 20));
    const Recorder::Stage& s = rec.stages.at("reading progress.bin");
    CHECK(s.total == bytes.size());
    CHECK(s.done == bytes.size());
    CHECK(s.unit == "bytes");
    Recorder stop(1);
    CHECK_THROWS_AS(readFileBytes(path, "test", &stop), InterruptedError);

    // Mapped, as the binary strand readers read: the same bytes, the same stage, the same stop.
    Recorder mapRec;
    {
        const MappedFile mapped(path, "test", &mapRec);
        REQUIRE(mapped.size() == bytes.size());
        CHECK(std::equal(bytes.begin(), bytes.end(), mapped.data()));
    }
    CHECK(mapRec.stages.at("reading progress.bin").done == bytes.size());
    Recorder mapStop(1);
    CHECK_THROWS_AS(MappedFile(path, "test", &mapStop), InterruptedError);
    CHECK(MappedFile(test::writeBytes("empty.bin", ""), "test").size() == 0);
    CHECK_THROWS_AS(MappedFile(test::tempPath("no such file"), "test"), IoError);

    // Through a strand reader's options.
    const StrandSet strands = manyStrands(8);
    const std::string hair = test::tempPath("progress.hair");
    writeStrands(hair, strands);
    ReadOptions opts;
    Recorder stopRead(1);
    opts.interrupter = &stopRead;
    CHECK_THROWS_AS(readStrands(hair, opts), InterruptedError);
}
