#include "track/mask_components.h"

#include <opencv2/imgproc.hpp>

namespace bouncefit {

int MaskComponents(const cv::Mat& mask, cv::Mat* labels, cv::Mat* stats, cv::Mat* centroids,
                   cv::Rect* box) {
  *box = cv::boundingRect(mask);
  if (box->area() == 0) {
    labels->release();
    return 1;
  }
  const int n = cv::connectedComponentsWithStats(mask(*box), *labels, *stats, *centroids, 8, CV_32S);
  for (int k = 1; k < n; ++k) {
    stats->at<int>(k, cv::CC_STAT_LEFT) += box->x;
    stats->at<int>(k, cv::CC_STAT_TOP) += box->y;
    centroids->at<double>(k, 0) += box->x;
    centroids->at<double>(k, 1) += box->y;
  }
  return n;
}

}  // namespace bouncefit
