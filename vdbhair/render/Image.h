/// @file Image.h
/// @brief A linear RGB float image, colour maps, text (FreeType, with a DejaVu font) and atomic
/// writing by extension: PNG with libpng, every other format OpenImageIO writes (EXR, JPEG, ...)
/// through the image module loaded on first use (ImageModule.h).
#pragma once

#include <vdbhair/Types.h>

#include <cstdint>
#include <string>
#include <vector>

namespace vdbhair {

struct Image
{
    int width = 0, height = 0;
    std::vector<float> rgb;  ///< #width·#height·3, row-major, top row first

    Image() = default;
    Image(int w, int h, const Vec3f& fill);
    Vec3f at(int x, int y) const { const float* p = &rgb[(std::size_t(y) * width + x) * 3]; return Vec3f(p[0], p[1], p[2]); }
    void set(int x, int y, const Vec3f& c) { float* p = &rgb[(std::size_t(y) * width + x) * 3]; p[0] = c.x(); p[1] = c.y(); p[2] = c.z(); }
    /// Copy @a other into this image with its top-left corner at (x, y).
    void paste(const Image& other, int x, int y);
};

/// @brief A display (sRGB-encoded) colour as the linear colour the image stores, so that it is
/// written back as itself.
Vec3f fromSrgb(const Vec3f& c);

/// @brief A linear value clamped to [0, 1] and sRGB-encoded (what 8-bit images store).
float linearToSrgb(float v);

/// @brief The image as 8-bit sRGB, #width·#height·3 bytes rounded to nearest: the bytes of a
/// written PNG (and of the arrays the Python module returns).
std::vector<std::uint8_t> toSrgb8(const Image& image);

/// @brief A perceptually ordered colour map (viridis-like) at t in [0, 1], linear.
Vec3f colorMap(float t);

/// @brief Hue (turns, any real), saturation and value in [0, 1] as a linear colour.
Vec3f hsvColor(double h, double s, double v);

/// @brief A colour for an integer id (strands, clusters), well spread in hue, linear.
Vec3f idColor(std::uint64_t id);

/// @brief Draw @a text with its left baseline at (x, y) in pixels, @a size pixels high.
/// Uses DejaVu Sans (Debian's fonts-dejavu-core); without it the text is skipped.
void drawText(Image& image, int x, int y, const std::string& text, int size, const Vec3f& color);

/// @brief A vertical colour bar at (x, y) of w × h pixels with @a label and the values of its
/// ends written beside it.
void drawColorBar(Image& image, int x, int y, int w, int h, double lo, double hi, const std::string& label);

/// @brief Write @a image to @a path (format by extension; 8-bit sRGB for PNG and JPEG, float
/// for EXR) through a temporary file renamed into place.
/// @throw ValueError (unknown extension), IoError.
void writeImage(const std::string& path, const Image& image);

/// @brief Whether @a path's extension is PNG or a format OpenImageIO can write (the latter loads
/// the image module).
bool isImagePath(const std::string& path);

} // namespace vdbhair
