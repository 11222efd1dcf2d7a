// `vdbhair` as a user runs it: a launcher that starts the vdbhair program (installed as
// libexec/vdbhair/vdbhair, next to bin/) with glibc's malloc asked for transparent huge pages.
//
// A command line whose first word is `info`, `help` or an option, or that has none, goes to the
// light program next to it instead (libexec/vdbhair/vdbhair-lite, lite/Lite.cc): the verbs' list
// and help and `info` of a strand file, without the 50 ms of loading OpenVDB. It hands on to the
// full program whatever it does not serve.
//
// A page fault costs about 20 µs on the virtual machines vdbhair is measured on (vdbhair/Memory.h),
// and glibc's malloc serves the many mid-sized blocks a verb allocates (OpenVDB's leaf buffers and
// point attribute arrays, k-d tree nodes, per-leaf vectors) from 4 KiB pages: their first touch
// was a large share of every verb. With glibc's tunable glibc.malloc.hugetlb=1 malloc asks the
// kernel for huge pages (madvise) for the memory it maps: reading a 92 MB strands .vdb went from
// 0.80 s to 0.18 s (45,000 page faults to 2,500). A tunable is read only from the environment a
// process starts with, and the program links OpenVDB, whose loading alone takes 70-85 ms here, so
// it cannot re-execute itself cheaply; this launcher links nothing but the C++ runtime and takes
// about a millisecond. An environment that already sets glibc.malloc.hugetlb keeps its value
// (GLIBC_TUNABLES=glibc.malloc.hugetlb=0 turns it off). jemalloc with huge pages was as fast, but
// under an address-space limit (`ulimit -v`, as batch schedulers set) it left no room for thread
// stacks, where vdbhair must say "out of memory" in one line (tests/apps/batch_test.sh).
#include <cerrno>
#include <climits>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>

#include <unistd.h>

#ifndef VDBHAIR_PROGRAM_RELATIVE
#error "VDBHAIR_PROGRAM_RELATIVE: the program's path relative to the launcher's folder"
#endif
#ifndef VDBHAIR_LITE_PROGRAM_RELATIVE
#error "VDBHAIR_LITE_PROGRAM_RELATIVE: the light program's path relative to the launcher's folder"
#endif

int main(int argc, char** argv)
{
    char self[PATH_MAX];
    const ssize_t n = ::readlink("/proc/self/exe", self, sizeof(self) - 1);
    if (n <= 0) {
        std::fprintf(stderr, "vdbhair: cannot find its own location (/proc/self/exe): %s\n", std::strerror(errno));
        return 127;
    }
    self[n] = '\0';
    std::string program(self);
    program.erase(program.rfind('/') + 1);
    const bool light = argc < 2 || argv[1][0] == '-' || std::strcmp(argv[1], "help") == 0 || std::strcmp(argv[1], "info") == 0;
    program += light ? VDBHAIR_LITE_PROGRAM_RELATIVE : VDBHAIR_PROGRAM_RELATIVE;
    const char* tunables = std::getenv("GLIBC_TUNABLES");
    if (!tunables || !std::strstr(tunables, "glibc.malloc.hugetlb")) {
        const std::string value = tunables && *tunables ? std::string(tunables) + ":glibc.malloc.hugetlb=1" : "glibc.malloc.hugetlb=1";
        ::setenv("GLIBC_TUNABLES", value.c_str(), 1);
    }
    ::execv(program.c_str(), argv);
    std::fprintf(stderr, "vdbhair: cannot start %s: %s\n", program.c_str(), std::strerror(errno));
    return 127;
}
