#include "Image.h"

#include <vdbhair/Exceptions.h>
#include <vdbhair/io/FileUtil.h>

#include <OpenImageIO/imagebuf.h>
#include <OpenImageIO/imagebufalgo.h>
#include <OpenImageIO/imageio.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>

namespace vdbhair {

Image::Image(int w, int h, const Vec3f& fill) : width(w), height(h), rgb(std::size_t(w) * std::size_t(h) * 3)
{
    for (std::size_t i = 0; i < std::size_t(w) * std::size_t(h); ++i) {
        rgb[3 * i] = fill.x(); rgb[3 * i + 1] = fill.y(); rgb[3 * i + 2] = fill.z();
    }
}

void Image::paste(const Image& o, int x0, int y0)
{
    for (int y = 0; y < o.height; ++y) {
        for (int x = 0; x < o.width; ++x) {
            if (x0 + x >= 0 && x0 + x < width && y0 + y >= 0 && y0 + y < height) set(x0 + x, y0 + y, o.at(x, y));
        }
    }
}

Vec3f fromSrgb(const Vec3f& c)
{
    auto f = [](float v) {
        v = std::min(1.f, std::max(0.f, v));
        return v <= 0.04045f ? v / 12.92f : std::pow((v + 0.055f) / 1.055f, 2.4f);
    };
    return Vec3f(f(c.x()), f(c.y()), f(c.z()));
}

Vec3f colorMap(float t)
{
    // Viridis, sampled at 9 points and interpolated linearly.
    static const float k[9][3] = {{0.267f, 0.005f, 0.329f}, {0.283f, 0.141f, 0.458f}, {0.254f, 0.265f, 0.530f},
                                  {0.207f, 0.372f, 0.553f}, {0.164f, 0.471f, 0.558f}, {0.128f, 0.567f, 0.551f},
                                  {0.135f, 0.659f, 0.518f}, {0.478f, 0.821f, 0.318f}, {0.993f, 0.906f, 0.144f}};
    t = std::min(1.f, std::max(0.f, std::isfinite(t) ? t : 0.f)) * 8.f;
    const int i = std::min(7, int(t));
    const float f = t - float(i);
    return fromSrgb(Vec3f(k[i][0] + (k[i + 1][0] - k[i][0]) * f, k[i][1] + (k[i + 1][1] - k[i][1]) * f, k[i][2] + (k[i + 1][2] - k[i][2]) * f));
}

Vec3f hsvColor(double h, double s, double v)
{
    h = (h - std::floor(h)) * 6.0;
    const double c = v * s, x = c * (1.0 - std::abs(std::fmod(h, 2.0) - 1.0)), m = v - c;
    double r = 0, g = 0, b = 0;
    switch (int(h)) {
    case 0: r = c; g = x; break;
    case 1: r = x; g = c; break;
    case 2: g = c; b = x; break;
    case 3: g = x; b = c; break;
    case 4: r = x; b = c; break;
    default: r = c; b = x; break;
    }
    return fromSrgb(Vec3f(float(r + m), float(g + m), float(b + m)));
}

Vec3f idColor(std::uint64_t id)
{
    // Golden-ratio hue steps, fixed saturation and value.
    return hsvColor(0.13 + double(id) * 0.6180339887498949, 0.65, 0.9);
}

namespace {
const char* fontPath()
{
    static const char* path = [] {
        for (const char* p : {"/usr/share/fonts/truetype/dejavu/DejaVuSans.ttf", "/usr/share/fonts/TTF/DejaVuSans.ttf",
                              "/usr/local/share/fonts/DejaVuSans.ttf"}) {
            std::error_code ec;
            if (std::filesystem::exists(p, ec)) return p;
        }
        return static_cast<const char*>(nullptr);
    }();
    return path;
}
} // namespace

void drawText(Image& image, int x, int y, const std::string& text, int size, const Vec3f& color)
{
    const char* font = fontPath();
    if (!font || image.width == 0) return;
    OIIO::ImageSpec spec(image.width, image.height, 3, OIIO::TypeDesc::FLOAT);
    OIIO::ImageBuf buf(spec, image.rgb.data());  // wraps our pixels
    const float c[3] = {color.x(), color.y(), color.z()};
    OIIO::ImageBufAlgo::render_text(buf, x, y, text, size, font, OIIO::cspan<float>(c, 3));
}

void drawColorBar(Image& image, int x, int y, int w, int h, double lo, double hi, const std::string& label)
{
    for (int j = 0; j < h; ++j) {
        const Vec3f c = colorMap(1.f - float(j) / float(std::max(1, h - 1)));
        for (int i = 0; i < w; ++i) {
            if (x + i >= 0 && x + i < image.width && y + j >= 0 && y + j < image.height) image.set(x + i, y + j, c);
        }
    }
    char buf[64];
    const int size = std::max(10, std::min(18, h / 12));
    std::snprintf(buf, sizeof buf, "%.4g", hi);
    drawText(image, x + w + 4, y + size, buf, size, Vec3f(0.f));
    std::snprintf(buf, sizeof buf, "%.4g", lo);
    drawText(image, x + w + 4, y + h, buf, size, Vec3f(0.f));
    drawText(image, x, y - 6, label, size, Vec3f(0.f));
}

bool isImagePath(const std::string& path)
{
    const std::string ext = fileExtension(path);
    if (ext.empty()) return false;
    auto out = OIIO::ImageOutput::create(path);
    return bool(out);
}

void writeImage(const std::string& path, const Image& image)
{
    const std::string where = "writeImage(" + path + ")";
    if (!isImagePath(path)) {
        throw ValueError(where + ": '" + fileExtension(path) + "' is not an image format OpenImageIO writes (use .png, .exr or .jpg)");
    }
    const std::string ext = fileExtension(path);
    const bool floatOut = ext == ".exr" || ext == ".hdr";
    AtomicOutput atomic(path);
    auto out = OIIO::ImageOutput::create(atomic.tempPath());
    if (!out) throw IoError(where + ": " + OIIO::geterror());
    OIIO::ImageSpec spec(image.width, image.height, 3, floatOut ? OIIO::TypeDesc::FLOAT : OIIO::TypeDesc::UINT8);
    spec.attribute("Software", "vdbhair");
    std::vector<float> pixels = image.rgb;
    if (!floatOut) {
        // Linear to sRGB for 8-bit formats.
        for (float& v : pixels) {
            v = std::min(1.f, std::max(0.f, v));
            v = v <= 0.0031308f ? 12.92f * v : 1.055f * std::pow(v, 1.f / 2.4f) - 0.055f;
        }
    }
    if (!out->open(atomic.tempPath(), spec) || !out->write_image(OIIO::TypeDesc::FLOAT, pixels.data()) || !out->close()) {
        throw IoError(where + ": " + out->geterror());
    }
    atomic.commit();
}

} // namespace vdbhair
