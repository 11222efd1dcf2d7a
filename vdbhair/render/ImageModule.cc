// The image module (ImageModule.h): OpenImageIO behind a C interface, loaded on first use.
#include "ImageModule.h"

#include <OpenImageIO/imageio.h>

#include <cstdio>
#include <string>

namespace {

int canWrite(const char* path)
{
    auto out = OIIO::ImageOutput::create(path);
    return out ? 1 : 0;
}

int write(const char* path, int width, int height, int asFloat, const float* rgb, char* err, std::size_t errSize)
{
    auto fail = [&](const std::string& what) {
        std::snprintf(err, errSize, "%s", what.c_str());
        return 1;
    };
    auto out = OIIO::ImageOutput::create(path);
    if (!out) return fail(OIIO::geterror());
    OIIO::ImageSpec spec(width, height, 3, asFloat ? OIIO::TypeDesc::FLOAT : OIIO::TypeDesc::UINT8);
    spec.attribute("Software", "vdbhair");
    if (!out->open(path, spec) || !out->write_image(OIIO::TypeDesc::FLOAT, rgb) || !out->close()) return fail(out->geterror());
    return 0;
}

const VdbhairImageModule kModule{kVdbhairImageModuleVersion, canWrite, write};

} // namespace

extern "C" __attribute__((visibility("default"))) const VdbhairImageModule* vdbhair_image_module()
{
    return &kModule;
}
