// The benchmark's machinery (Harness.h).
#include "Harness.h"

#include <vdbhair/strands/Resample.h>

#include <sys/resource.h>
#include <sys/wait.h>
#include <fcntl.h>
#include <unistd.h>

#include <chrono>
#include <random>

namespace vdbhair::bench {

double now()
{
    return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

double peakMiB()
{
    rusage u{};
    getrusage(RUSAGE_SELF, &u);
    return double(u.ru_maxrss) / 1024.0;
}

StrandSet jitteredCopies(const StrandSet& base, std::size_t count, std::size_t vertices, float jitter)
{
    const StrandSet b = resampleStrands(base, vertices);
    StrandSet out;
    out.reserve(count, count * vertices);
    std::normal_distribution<float> n(0.f, jitter);
    for (std::size_t i = 0; i < count; ++i) {
        const std::size_t src = i % b.numStrands();
        std::mt19937 rng(std::uint32_t(i * 2654435761u + 17u));
        const Vec3f d(n(rng), n(rng), n(rng));
        std::vector<Vec3f> pts(b.data(src), b.data(src) + vertices);
        for (Vec3f& p : pts) p += d;
        out.addStrand(pts);
    }
    return out;
}

ProcessRun runProcess(const std::vector<std::string>& args, const std::string& stdoutPath)
{
    std::vector<char*> argv;
    for (const std::string& a : args) argv.push_back(const_cast<char*>(a.c_str()));
    argv.push_back(nullptr);
    const double t0 = now();
    const pid_t pid = fork();
    if (pid == 0) {
        const int devNull = open("/dev/null", O_WRONLY);
        const int out = stdoutPath.empty() ? devNull : open(stdoutPath.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
        dup2(out, 1);
        dup2(devNull, 2);
        execv(argv[0], argv.data());
        _exit(127);
    }
    ProcessRun r;
    rusage u{};
    if (pid < 0 || wait4(pid, &r.status, 0, &u) != pid) {
        r.status = -1;
        return r;
    }
    r.wall = now() - t0;
    r.cpu = double(u.ru_utime.tv_sec + u.ru_stime.tv_sec) + 1e-6 * double(u.ru_utime.tv_usec + u.ru_stime.tv_usec);
    r.peakMiB = double(u.ru_maxrss) / 1024.0;
    return r;
}

} // namespace vdbhair::bench
