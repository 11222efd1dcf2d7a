/// @file FeatureImage.h
/// @brief A multi-channel 2D map on a regular grid with a validity mask: the feature maps of
/// Wang et al. (2009, §5.1), whose pixels hold the PCA feature vectors of strands at regularly
/// spaced (u, v) points of the scalp.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

namespace vdbhair {

/// @brief Row-major, channel-interleaved: the value of channel c at pixel (x, y) is
/// `data[(y * width + x) * channels + c]`. `valid[y * width + x]` is 1 where the map is defined
/// (e.g. where the scalp has hair) and 0 elsewhere; an empty `valid` means every pixel is valid.
struct FeatureImage
{
    int width = 0, height = 0, channels = 0;
    std::vector<float> data;
    std::vector<std::uint8_t> valid;

    FeatureImage() = default;
    FeatureImage(int w, int h, int c)
        : width(w), height(h), channels(c), data(std::size_t(w) * h * c, 0.0f), valid(std::size_t(w) * h, 1)
    {
    }

    std::size_t pixelCount() const { return std::size_t(width) * std::size_t(height); }
    float* pixel(int x, int y) { return data.data() + (std::size_t(y) * width + x) * channels; }
    const float* pixel(int x, int y) const { return data.data() + (std::size_t(y) * width + x) * channels; }
    bool isValid(int x, int y) const { return valid.empty() || valid[std::size_t(y) * width + x] != 0; }
};

} // namespace vdbhair
