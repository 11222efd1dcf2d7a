// Uses an installed vdbhair: a strand of known length, measured by the library.
#include <vdbhair/Version.h>
#include <vdbhair/strands/Measures.h>
#include <vdbhair/strands/StrandSet.h>

#include <cstdio>

int main()
{
    vdbhair::StrandSet s;
    s.addStrand({vdbhair::Vec3f(0.f, 0.f, 0.f), vdbhair::Vec3f(3.f, 4.f, 0.f), vdbhair::Vec3f(3.f, 4.f, 12.f)});
    const double length = vdbhair::polylineLength(s.data(0), s.size(0));
    std::printf("%s: 1 strand of length %g\n", vdbhair::creatorString(), length);
    return length == 17.0 ? 0 : 1;
}
