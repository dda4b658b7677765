#pragma once

// The pixels of a rim's band that the sensor clipped, fitted as censored observations.
//
// An overexposed backlight reads 255 (an 8-bit image; 65535 in a 16-bit one) wherever its light
// exceeds that, and an underexposed part reads 0: the step across such a rim is cut on that side,
// its 50% level moved towards the other. Fitted as it reads, a hole in a background a quarter over
// the clip came out 0.33 px small, half over 0.57 px (r = 40 px, blur 1). A pixel at a limit only
// says that the grey there is at or beyond it: where the model is too, the pixel has no residual
// and no weight (the model is clipped as the sensor clips); where the model falls short, the
// pixel pulls it as any other does. The levels beyond the clip are then fitted from the slope of
// the step's visible part. (A Tobit likelihood would weigh how probable each clipped reading is;
// it differs from this hinge only for pixels whose model lies within a few noise levels of the
// limit, a thin ring next to the clipped side.)

#include <cstddef>
#include <span>
#include <vector>

namespace facet {

class CensoredPixels {
 public:
  CensoredPixels() = default;
  // `grey`: the band's grey values, on the scale where `clipLevel` is the sensor's largest value
  // (sensorLimit, algorithms/image/sensor_limit.hpp); the pixels at it or at 0 are the censored
  // ones.
  CensoredPixels(std::span<const double> grey, double clipLevel);

  [[nodiscard]] bool empty() const { return index_.empty(); }
  [[nodiscard]] std::size_t size() const { return index_.size(); }

  // Residuals (grey - model): a clipped pixel's is set to zero where the model lies at or beyond
  // its limit.
  void censor(std::span<double> residuals) const;
  // Weights of the pixels censor() zeroed set to zero (an exact zero residual of a clipped pixel
  // otherwise needs the model exactly at the limit).
  void unweight(std::span<const double> residuals, std::span<double> weights) const;
  // rim_band::robustSigma of the residuals of the pixels within the sensor's range. A clipped
  // pixel's residual is no noise: censored it is zero, and where the model sits just inside the
  // limit it is tiny; counted, they made the noise level collapse when a fit's level reached
  // the clip (the robust weights then kept a few pixels, and the fit stuck there, 0.6 px off).
  [[nodiscard]] double robustSigma(std::span<const double> residuals) const;
  // A starting level for a side of the step whose median `level` reads at a limit (`other`: the
  // other side's): beyond the limit by half the step that is seen, so that the fit starts with
  // that side censored rather than at the limit, next to the fit of the pixels as they read.
  [[nodiscard]] static double startingLevel(double level, double other, double clipLevel);
  // The starting outside level and contrast (inside minus outside) of a step whose sides' medians
  // read `outside` and `inside`: startingLevel for each side.
  struct Step {
    double level, contrast;
  };
  [[nodiscard]] static Step startingStep(double outside, double inside, double clipLevel);
  // Whether a step from `level` by `contrast` (either sign) has its middle within the sensor's
  // range: beyond it, the rim is not seen but extrapolated from the foot of its step (holes in a
  // background 2.4 times the clip came out 0.06-0.7 px small), and no fit of it is kept.
  [[nodiscard]] bool middleSeen(double level, double contrast) const;

 private:
  std::vector<std::size_t> index_;  // ascending
  std::vector<bool> high_;          // of each: at the upper limit (else at 0)
  double clipLevel_ = 255.0;
};

}  // namespace facet
