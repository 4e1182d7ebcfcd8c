#include "track/inscribed_disc.h"

#include <opencv2/imgproc.hpp>

namespace bouncefit {

InscribedDisc LargestInscribedDisc(const cv::Mat& mask, cv::Rect box, bool open_left, bool open_top,
                                   bool open_right, bool open_bottom) {
  InscribedDisc out;
  box &= cv::Rect(0, 0, mask.cols, mask.rows);
  if (box.width < 3 || box.height < 3) return out;
  // One pixel of border around the box: unset where the blob ends there, set where the
  // picture's border cut it (the blob goes on, unseen). Open sides reach a box further out.
  const int pad = 1 + static_cast<int>(0.5 * std::max(box.width, box.height));
  const int l = open_left ? pad : 1, t = open_top ? pad : 1, r = open_right ? pad : 1, b = open_bottom ? pad : 1;
  cv::Mat padded(box.height + t + b, box.width + l + r, CV_8U, cv::Scalar(0));
  cv::Mat inner = padded(cv::Rect(l, t, box.width, box.height));
  cv::compare(mask(box), 0, inner, cv::CMP_NE);
  // An open side: the blob's last row or column carried on outwards.
  for (int k = 0; k < l; ++k) inner.col(0).copyTo(padded(cv::Rect(k, t, 1, box.height)));
  for (int k = 0; k < r; ++k) inner.col(box.width - 1).copyTo(padded(cv::Rect(l + box.width + k, t, 1, box.height)));
  for (int k = 0; k < t; ++k) padded.row(t).copyTo(padded.row(k));
  for (int k = 0; k < b; ++k) padded.row(t + box.height - 1).copyTo(padded.row(t + box.height + k));
  cv::Mat dist;
  cv::distanceTransform(padded, dist, cv::DIST_L2, cv::DIST_MASK_PRECISE);
  double best = 0;
  cv::Point at;
  cv::minMaxLoc(dist(cv::Rect(l, t, box.width, box.height)), nullptr, &best, nullptr, &at);
  if (!(best > 1)) return out;
  out.ok = true;
  out.cx = box.x + at.x;
  out.cy = box.y + at.y;
  out.r = best;
  return out;
}

}  // namespace bouncefit
