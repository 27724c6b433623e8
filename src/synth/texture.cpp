#include "synth/texture.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "common/error.hpp"
#include "common/look_alikes.hpp"

namespace hiveslam::synth {

Texture::Texture(cv::Mat level0, double density) : density_(density) {
  levels_.push_back(std::move(level0));
  while (std::min(levels_.back().cols, levels_.back().rows) > 2) {
    cv::Mat next;
    cv::pyrDown(levels_.back(), next);  // Gaussian pre-filter, then decimation
    levels_.push_back(next);
  }
}

float Texture::bilinear(int level, double x0, double y0) const {
  const cv::Mat& m = levels_[static_cast<size_t>(level)];
  const double s = 1.0 / static_cast<double>(1 << level);
  // pyrDown centres texel j of level L on level-0 texel 2^L j (continuous 2^L j + 0.5).
  const double x = std::clamp((x0 - 0.5) * s, 0.0, m.cols - 1.0);
  const double y = std::clamp((y0 - 0.5) * s, 0.0, m.rows - 1.0);
  const int ix = std::min(static_cast<int>(x), m.cols - 2 < 0 ? 0 : m.cols - 2);
  const int iy = std::min(static_cast<int>(y), m.rows - 2 < 0 ? 0 : m.rows - 2);
  const float fx = static_cast<float>(x - ix), fy = static_cast<float>(y - iy);
  const uchar* r0 = m.ptr<uchar>(iy);
  const uchar* r1 = m.rows > 1 ? m.ptr<uchar>(iy + 1) : r0;
  const int ix1 = m.cols > 1 ? ix + 1 : ix;
  const float top = r0[ix] + fx * (r0[ix1] - r0[ix]);
  const float bottom = r1[ix] + fx * (r1[ix1] - r1[ix]);
  return top + fy * (bottom - top);
}

float Texture::sample(double u, double v, double minor, double major, double du, double dv) const {
  // Up to 4 taps along the major axis; the level is chosen for the spacing between taps.
  const double ratio = major / std::max(minor, 1e-12);
  const int taps = std::clamp(static_cast<int>(std::ceil(ratio)), 1, 4);
  const double step = major / taps;
  const double footprint = std::max(step, minor) * density_;
  const double lod = std::clamp(std::log2(std::max(footprint, 1e-9)), 0.0, levels() - 1.0);
  const int l0 = static_cast<int>(lod);
  const int l1 = std::min(l0 + 1, levels() - 1);
  const float w = static_cast<float>(lod - l0);
  float sum = 0.0f;
  for (int k = 0; k < taps; ++k) {
    const double o = (k + 0.5 - 0.5 * taps) * step;
    const double x = (u + o * du) * density_, y = (v + o * dv) * density_;
    const float a = bilinear(l0, x, y);
    sum += w > 0.0f ? a + w * (bilinear(l1, x, y) - a) : a;
  }
  return sum / static_cast<float>(taps);
}

namespace {

double uniform(std::mt19937_64& rng, double a, double b) {
  return std::uniform_real_distribution<double>(a, b)(rng);
}

cv::Size texelSize(double width_m, double height_m, double density) {
  return {std::max(2, static_cast<int>(std::ceil(width_m * density))),
          std::max(2, static_cast<int>(std::ceil(height_m * density)))};
}

}  // namespace

Texture makeProceduralTexture(double width_m, double height_m, double density, std::mt19937_64& rng) {
  const cv::Size size = texelSize(width_m, height_m, density);
  // Low-frequency blotches: a coarse random grid (one cell per ~30 cm) upsampled smoothly.
  cv::Mat coarse(std::max(2, static_cast<int>(height_m / 0.3)), std::max(2, static_cast<int>(width_m / 0.3)),
                 CV_32F);
  for (int r = 0; r < coarse.rows; ++r)
    for (int c = 0; c < coarse.cols; ++c) coarse.at<float>(r, c) = static_cast<float>(uniform(rng, 70, 190));
  cv::Mat base;
  cv::resize(coarse, base, size, 0, 0, cv::INTER_CUBIC);
  cv::Mat img;
  base.convertTo(img, CV_8U);

  // Shapes, sized log-uniformly, drawn largest first so small detail stays visible.
  const double area = width_m * height_m;
  const int count = static_cast<int>(area * 45.0) + 4;
  struct Shape {
    double size;
    int kind;
  };
  std::vector<Shape> shapes;
  for (int i = 0; i < count; ++i)
    shapes.push_back({std::exp(uniform(rng, std::log(0.03), std::log(0.5))),
                      static_cast<int>(uniform(rng, 0, 5))});
  std::sort(shapes.begin(), shapes.end(), [](const Shape& a, const Shape& b) { return a.size > b.size; });
  constexpr int kShift = 3;
  const double sub = density * (1 << kShift);
  for (const Shape& s : shapes) {
    const double cx = uniform(rng, -0.1, width_m + 0.1), cy = uniform(rng, -0.1, height_m + 0.1);
    const double angle = uniform(rng, 0, 2 * M_PI);
    const cv::Scalar gray(std::round(uniform(rng, 0, 255)));
    std::vector<cv::Point> poly;
    auto add = [&](double x, double y) {
      poly.emplace_back(cvRound((cx + x) * sub), cvRound((cy + y) * sub));
    };
    const double r = 0.5 * s.size;
    switch (s.kind) {
      case 0: {  // rectangle of random aspect
        const double a = r, b = r * uniform(rng, 0.3, 1.0);
        for (auto [x, y] : {std::pair{-a, -b}, {a, -b}, {a, b}, {-a, b}})
          add(x * std::cos(angle) - y * std::sin(angle), x * std::sin(angle) + y * std::cos(angle));
        break;
      }
      case 1:  // triangle
      case 2: {  // irregular polygon / star
        const int n = s.kind == 1 ? 3 : static_cast<int>(uniform(rng, 5, 9));
        for (int k = 0; k < n; ++k) {
          const double t = angle + 2 * M_PI * k / n;
          const double rr = r * (s.kind == 2 && k % 2 ? uniform(rng, 0.35, 0.7) : 1.0);
          add(rr * std::cos(t), rr * std::sin(t));
        }
        break;
      }
      case 3:  // ellipse
        cv::ellipse(img, cv::Point(cvRound(cx * sub), cvRound(cy * sub)),
                    cv::Size(cvRound(r * sub), cvRound(r * uniform(rng, 0.4, 1.0) * sub)),
                    angle * 180 / M_PI, 0, 360, gray, cv::FILLED, cv::LINE_AA, kShift);
        break;
      default: {  // stroke
        const double len = 2 * r;
        cv::line(img, cv::Point(cvRound(cx * sub), cvRound(cy * sub)),
                 cv::Point(cvRound((cx + len * std::cos(angle)) * sub), cvRound((cy + len * std::sin(angle)) * sub)),
                 gray, std::max(1, static_cast<int>(density * uniform(rng, 0.005, 0.02))), cv::LINE_AA, kShift);
        break;
      }
    }
    if (!poly.empty()) cv::fillPoly(img, std::vector<std::vector<cv::Point>>{poly}, gray, cv::LINE_AA, kShift);
  }
  return Texture(img, density);
}

Texture makePhotoTexture(double width_m, double height_m, double density,
                         const std::vector<cv::Mat>& photos, std::mt19937_64& rng, double contrast) {
  const cv::Size size = texelSize(width_m, height_m, density);
  const cv::Mat& photo = photos[static_cast<size_t>(uniform(rng, 0, static_cast<double>(photos.size()))) % photos.size()];
  const double tile_m = uniform(rng, 0.8, 2.0);
  const int tw = std::max(8, static_cast<int>(tile_m * density));
  const int th = std::max(8, static_cast<int>(tw * photo.rows / static_cast<double>(photo.cols)));
  cv::Mat tile;
  cv::resize(photo, tile, {tw, th}, 0, 0, cv::INTER_AREA);
  if (uniform(rng, 0, 1) < 0.5) cv::flip(tile, tile, 1);
  // Mirrored tiling keeps the seams continuous; a random offset shifts the repeat.
  const int ox = static_cast<int>(uniform(rng, 0, tw)), oy = static_cast<int>(uniform(rng, 0, th));
  cv::Mat img(size, CV_8U);
  for (int y = 0; y < size.height; ++y) {
    const int ty = (y + oy) % (2 * th);
    const uchar* row = tile.ptr<uchar>(ty < th ? ty : 2 * th - 1 - ty);
    uchar* out = img.ptr<uchar>(y);
    for (int x = 0; x < size.width; ++x) {
      const int tx = (x + ox) % (2 * tw);
      out[x] = row[tx < tw ? tx : 2 * tw - 1 - tx];
    }
  }
  if (contrast != 1.0) {
    const double mean = cv::mean(img)[0];
    img.convertTo(img, CV_8U, contrast, mean * (1.0 - contrast));
  }
  return Texture(img, density);
}

Texture makePlainTexture(double width_m, double height_m, double density, double grey, std::mt19937_64& rng) {
  const cv::Size size = texelSize(width_m, height_m, density);
  // Variations of +-3% over about a metre: uneven paint and light that the lamps do not explain.
  cv::Mat coarse(std::max(2, static_cast<int>(height_m / 1.0) + 1), std::max(2, static_cast<int>(width_m / 1.0) + 1),
                 CV_32F);
  for (int r = 0; r < coarse.rows; ++r)
    for (int c = 0; c < coarse.cols; ++c) coarse.at<float>(r, c) = static_cast<float>(grey * uniform(rng, 0.97, 1.03));
  cv::Mat base;
  cv::resize(coarse, base, size, 0, 0, cv::INTER_CUBIC);
  cv::Mat img;
  base.convertTo(img, CV_8U);
  // About one faint mark per square metre, 1-8 cm, 4-15 grey levels off the paint.
  const int marks = static_cast<int>(width_m * height_m * 1.0);
  for (int i = 0; i < marks; ++i) {
    const cv::Point c(static_cast<int>(uniform(rng, 0, size.width)), static_cast<int>(uniform(rng, 0, size.height)));
    const int r = std::max(1, static_cast<int>(density * uniform(rng, 0.005, 0.04)));
    const double sign = uniform(rng, 0, 1) < 0.7 ? -1.0 : 1.0;
    const cv::Scalar shade(std::clamp(grey + sign * uniform(rng, 4, 15), 0.0, 255.0));
    if (uniform(rng, 0, 1) < 0.5)
      cv::circle(img, c, r, shade, cv::FILLED, cv::LINE_AA);
    else
      cv::line(img, c, c + cv::Point(static_cast<int>(uniform(rng, -2, 2) * r), static_cast<int>(uniform(rng, -2, 2) * r)),
               shade, std::max(1, r / 4), cv::LINE_AA);
  }
  return Texture(img, density);
}

std::vector<cv::Mat> loadPhotos(const std::string& folder, double max_look_alikes) {
  namespace fs = std::filesystem;
  if (!fs::is_directory(folder)) throw InputError("texture folder not found: " + folder);
  std::vector<fs::path> files;
  for (const auto& e : fs::directory_iterator(folder)) {
    std::string ext = e.path().extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(), ::tolower);
    if (ext == ".jpg" || ext == ".jpeg" || ext == ".png") files.push_back(e.path());
  }
  std::sort(files.begin(), files.end());
  std::vector<cv::Mat> photos;
  for (const auto& f : files) {
    cv::Mat m = cv::imread(f.string(), cv::IMREAD_GRAYSCALE);
    if (m.empty() || m.cols < 64 || m.rows < 64) continue;
    if (max_look_alikes < 1.0) {
      cv::Mat at640;
      cv::resize(m, at640, {}, 640.0 / m.cols, 640.0 / m.cols, cv::INTER_AREA);
      if (lookAlikeShare(at640) > max_look_alikes) continue;
    }
    photos.push_back(m);
  }
  if (photos.empty())
    throw InputError(fmt::format("no usable photos (jpg/png, at least 64x64, look-alike share at most {}) in {}",
                                 max_look_alikes, folder));
  return photos;
}

}  // namespace hiveslam::synth
