#include "track/shrink.h"

#include <opencv2/imgproc.hpp>

#include <stdexcept>

namespace bouncefit {

void ShrinkByBlocks(const cv::Mat& src, cv::Mat* dst, int factor) {
  if (factor < 1 || (factor & (factor - 1)) != 0)
    throw std::invalid_argument("ShrinkByBlocks: factor must be a power of two");
  const cv::Size target(src.cols / factor, src.rows / factor);
  if (factor == 1) {
    src.copyTo(*dst);
    return;
  }
  cv::Mat a, b;
  const cv::Mat* from = &src;
  for (int f = factor; f > 1; f /= 2) {
    // The last step lands on the exact target size (the block grid of the original).
    cv::Mat& to = f == 2 ? *dst : (from == &a ? b : a);
    const cv::Size next = f == 2 ? target : cv::Size(from->cols / 2, from->rows / 2);
    cv::resize(*from, to, next, 0, 0, cv::INTER_LINEAR);
    from = &to;
  }
}

}  // namespace bouncefit
