// NAFF (see frequency_analysis.hpp). Everything runs in the normalised frequency u = omega tau (radians per sample)
// and the centred sample index x_k = k - c, c = (N-1)/2; the time scale tau enters only at the end.
#include "nonsep/core/analysis/frequency_analysis.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <limits>
#include <map>
#include <numbers>
#include <string>
#include <unsupported/Eigen/FFT>
#include <utility>

#include "nonsep/core/base/error.hpp"

namespace nonsep {

namespace {

constexpr double two_pi = 2.0 * std::numbers::pi;

// exp(-i u x_k) for the N centred indices x_k = k - c, as base(b) * step(j) with k = b B + j: B steps and N/B bases
// from std::cos and std::sin, each product exact to a few ulp (a rotation by repeated multiplication would drift by
// one ulp per sample). B ~ sqrt(N) keeps the 2 sqrt(N) sines and cosines small against the N products, which are
// kept in two arrays (re, im) that the sums below read in lanes.
class Exponentials {
 public:
  void set(double u, std::size_t n) {
    const auto block = static_cast<std::size_t>(std::ceil(std::sqrt(static_cast<double>(n))));
    const std::size_t blocks = (n + block - 1) / block;
    step_re_.resize(block);
    step_im_.resize(block);
    re_.resize(n);
    im_.resize(n);
    const double centre = 0.5 * static_cast<double>(n - 1);
    for (std::size_t j = 0; j < block; ++j) {
      const double angle = -u * static_cast<double>(j);
      step_re_[j] = std::cos(angle);
      step_im_[j] = std::sin(angle);
    }
    for (std::size_t b = 0; b < blocks; ++b) {
      const double angle = -u * (static_cast<double>(b * block) - centre);
      const double br = std::cos(angle), bi = std::sin(angle);
      const std::size_t k0 = b * block, end = std::min(block, n - k0);
      for (std::size_t j = 0; j < end; ++j) {
        re_[k0 + j] = br * step_re_[j] - bi * step_im_[j];
        im_[k0 + j] = br * step_im_[j] + bi * step_re_[j];
      }
    }
  }

  std::size_t size() const { return re_.size(); }
  const double* re() const { return re_.data(); }
  const double* im() const { return im_.data(); }

 private:
  std::vector<double> step_re_, step_im_, re_, im_;
};

// Sums over k in `lanes` independent partial sums (k mod lanes), added at the end: the loops vectorise without
// reassociation by the compiler, and the sums are as accurate as one running sum or more. Each loop writes its body
// twice, for the whole groups and for the rest: with the body as one lambda called from both, GCC 12 no longer
// vectorised the moments (perf annotate: no packed instructions, the sums 40% slower).
constexpr std::size_t lanes = 4;

// sum_k w_k exp(-i u x_k) x_k^p for p = 0, 1, 2 (w = chi times the signal, split into real and imaginary parts).
struct Moments {
  std::complex<double> s0, s1, s2;
};

Moments moments(const Exponentials& e, const std::vector<double>& w_re, const std::vector<double>& w_im) {
  const std::size_t n = e.size();
  const double centre = 0.5 * static_cast<double>(n - 1);
  const double *er = e.re(), *ei = e.im(), *wr = w_re.data(), *wi = w_im.data();
  double s[6][lanes] = {};
  std::size_t k = 0;
  for (; k + lanes <= n; k += lanes)
    for (std::size_t l = 0; l < lanes; ++l) {
      const double pr = wr[k + l] * er[k + l] - wi[k + l] * ei[k + l];
      const double pi = wr[k + l] * ei[k + l] + wi[k + l] * er[k + l];
      const double x = static_cast<double>(k + l) - centre;
      s[0][l] += pr;
      s[1][l] += pi;
      s[2][l] += x * pr;
      s[3][l] += x * pi;
      s[4][l] += x * x * pr;
      s[5][l] += x * x * pi;
    }
  for (std::size_t l = 0; k < n; ++k, ++l) {
    const double pr = wr[k] * er[k] - wi[k] * ei[k], pi = wr[k] * ei[k] + wi[k] * er[k];
    const double x = static_cast<double>(k) - centre;
    s[0][l] += pr;
    s[1][l] += pi;
    s[2][l] += x * pr;
    s[3][l] += x * pi;
    s[4][l] += x * x * pr;
    s[5][l] += x * x * pi;
  }
  double t[6];
  for (std::size_t i = 0; i < 6; ++i) t[i] = (s[i][0] + s[i][1]) + (s[i][2] + s[i][3]);
  return {{t[0], t[1]}, {t[2], t[3]}, {t[4], t[5]}};
}

std::complex<double> transform(const Exponentials& e, const std::vector<double>& w_re,
                               const std::vector<double>& w_im) {
  const std::size_t n = e.size();
  const double *er = e.re(), *ei = e.im(), *wr = w_re.data(), *wi = w_im.data();
  double sr[lanes] = {}, si[lanes] = {};
  std::size_t k = 0;
  for (; k + lanes <= n; k += lanes)
    for (std::size_t l = 0; l < lanes; ++l) {
      sr[l] += wr[k + l] * er[k + l] - wi[k + l] * ei[k + l];
      si[l] += wr[k + l] * ei[k + l] + wi[k + l] * er[k + l];
    }
  for (std::size_t l = 0; k < n; ++k, ++l) {
    sr[l] += wr[k] * er[k] - wi[k] * ei[k];
    si[l] += wr[k] * ei[k] + wi[k] * er[k];
  }
  return {(sr[0] + sr[1]) + (sr[2] + sr[3]), (si[0] + si[1]) + (si[2] + si[3])};
}

// sum_k chi_k exp(-i u x_k), real since chi is symmetric about the centre.
double window_transform(const Exponentials& e, const std::vector<double>& chi) {
  const std::size_t n = e.size();
  const double* er = e.re();
  double sum[lanes] = {};
  std::size_t k = 0;
  for (; k + lanes <= n; k += lanes)
    for (std::size_t l = 0; l < lanes; ++l) sum[l] += chi[k + l] * er[k + l];
  for (std::size_t l = 0; k < n; ++k, ++l) sum[l] += chi[k] * er[k];
  return (sum[0] + sum[1]) + (sum[2] + sum[3]);
}

double wrap(double u) {  // into [-pi, pi)
  u = std::remainder(u, two_pi);
  return u >= std::numbers::pi ? u - two_pi : u;
}

}  // namespace

struct FrequencyAnalysis::Workspace {
  Eigen::FFT<double> fft;
  std::vector<std::complex<double>> padded, spectrum;
  // The window of each length seen, kept: a frequency map alternates between a run's samples and its halves. At most
  // kept_windows lengths (an object that lives long, one per thread, sees the lengths of early-retired trajectories).
  static constexpr std::size_t kept_windows = 4;
  struct Window {
    std::vector<double> chi;  // chi_k
    double sum = 0.0;         // sum_k chi_k
  };
  std::map<std::size_t, Window> windows;
  std::vector<double> window;                    // chi_k of the current length
  double window_sum = 0.0;                       // sum_k chi_k
  std::vector<double> signal_re, signal_im;      // chi_k z_k
  std::vector<double> residual_re, residual_im;  // chi_k r_k
  Exponentials exponentials;

  void prepare(std::span<const std::complex<double>> z) {
    const std::size_t n = z.size();
    if (window.size() != n) {
      if (!windows.contains(n) && windows.size() >= kept_windows) windows.clear();
      const auto found = windows.try_emplace(n);
      Window& known = found.first->second;
      if (found.second) {
        // chi_k = 1 - cos(2 pi k / (N-1)) = 1 + cos(u x_k) with u = 2 pi / (N-1).
        known.chi.resize(n);
        exponentials.set(two_pi / static_cast<double>(n - 1), n);
        for (std::size_t k = 0; k < n; ++k) {
          known.chi[k] = 1.0 + exponentials.re()[k];
          known.sum += known.chi[k];
        }
      }
      window = known.chi;
      window_sum = known.sum;
    }
    signal_re.resize(n);
    signal_im.resize(n);
    for (std::size_t k = 0; k < n; ++k) {
      signal_re[k] = window[k] * z[k].real();
      signal_im[k] = window[k] * z[k].imag();
    }
    residual_re = signal_re;
    residual_im = signal_im;
  }

  // The strongest frequency u of the residual (not wrapped into [-pi, pi): exp(-i u x_k) changes with u by 2 pi when
  // N is even), by the FFT's peak and Newton's method on d|phi|^2/du, and the residual's transform there,
  // sum_k chi_k r_k exp(-i u x_k).
  struct Peak {
    double u;
    std::complex<double> transform;
  };
  Peak strongest_frequency() {
    const std::size_t n = residual_re.size(), m = std::bit_ceil(n);
    padded.assign(m, {0.0, 0.0});
    for (std::size_t k = 0; k < n; ++k) padded[k] = {residual_re[k], residual_im[k]};
    spectrum.resize(m);
    fft.fwd(spectrum.data(), padded.data(), static_cast<Eigen::Index>(m));
    std::size_t peak = 0;
    double peak_norm = -1.0;
    for (std::size_t j = 0; j < m; ++j) {
      const double norm = std::norm(spectrum[j]);
      if (norm > peak_norm) peak_norm = norm, peak = j;
    }
    const double grid = two_pi / static_cast<double>(m);
    // A parabola through the logarithms of the three bins at the peak (exact for a Gaussian lobe; a good start
    // for Hann's).
    const double left = std::abs(spectrum[(peak + m - 1) % m]), right = std::abs(spectrum[(peak + 1) % m]);
    const double centre = std::abs(spectrum[peak]);
    double offset = 0.0;
    if (left > 0.0 && right > 0.0 && centre > 0.0) {
      const double l = std::log(left), c = std::log(centre), r = std::log(right);
      const double curvature = l - 2.0 * c + r;
      if (curvature < 0.0) offset = std::clamp(0.5 * (l - r) / curvature, -0.5, 0.5);
    }
    const double peak_u = grid * static_cast<double>(peak);
    double lo = peak_u - grid, hi = peak_u + grid, u = peak_u + offset * grid;
    // Newton's error after a step d is about K d^2 with K ~ 0.01 / grid on a Hann lobe: a step below 1e-6 of the
    // grid leaves an error below 1e-12 of it, round-off. From the parabola's start (within some 5e-3 of the grid)
    // that is two passes.
    const double tolerance = 1e-6 * grid;
    Moments s{};
    double step = 0.0;
    for (int iteration = 0; iteration < 100; ++iteration) {
      exponentials.set(u, n);
      s = moments(exponentials, residual_re, residual_im);
      // |phi|^2 up to a positive factor is |s0|^2; its first and second derivatives in u:
      const double slope = 2.0 * (std::conj(s.s0) * s.s1).imag();
      const double curvature = 2.0 * (std::norm(s.s1) - (std::conj(s.s0) * s.s2).real());
      step = 0.0;
      if (slope == 0.0) break;
      (slope > 0.0 ? lo : hi) = u;
      step = -slope / curvature;
      // The last step may land on the bracket's end, which is u itself to the last bit.
      if (curvature < 0.0 && std::abs(step) <= tolerance) break;
      if (!(curvature < 0.0) || !(u + step > lo && u + step < hi)) step = 0.5 * (lo + hi) - u;
      u += step;
      if (hi - lo <= 4.0 * std::numeric_limits<double>::epsilon() * std::max(std::abs(u), grid)) {
        step = 0.0;
        exponentials.set(u, n);
        s = moments(exponentials, residual_re, residual_im);
        break;
      }
    }
    // The transform at u + step from the moments at u (Taylor; the next term, (step N/2)^3 / 6, is below 1e-18).
    const std::complex<double> i_step{0.0, step};
    return {u + step, s.s0 - i_step * s.s1 + 0.5 * i_step * i_step * s.s2};
  }
};

FrequencyAnalysis::FrequencyAnalysis() : workspace_(std::make_unique<Workspace>()) {}
FrequencyAnalysis::~FrequencyAnalysis() = default;
FrequencyAnalysis::FrequencyAnalysis(FrequencyAnalysis&&) noexcept = default;
FrequencyAnalysis& FrequencyAnalysis::operator=(FrequencyAnalysis&&) noexcept = default;

std::vector<FrequencyTerm> FrequencyAnalysis::terms(std::span<const std::complex<double>> samples, double tau,
                                                    std::size_t count) {
  const std::string where = "frequency analysis: ";
  if (samples.size() < minimum_samples)
    throw InvalidArgument(where + std::to_string(samples.size()) + " samples, at least " +
                          std::to_string(minimum_samples) + " needed");
  if (!std::isfinite(tau) || !(tau > 0.0))
    throw InvalidArgument(where + "the sampling interval tau must be finite and positive (found " + found_number(tau) +
                          ")");
  if (count == 0) throw InvalidArgument(where + "asked for 0 terms, at least 1 needed");
  for (std::size_t k = 0; k < samples.size(); ++k)
    if (!std::isfinite(samples[k].real()) || !std::isfinite(samples[k].imag()))
      throw InvalidArgument(where + "sample " + std::to_string(k) + " of " + std::to_string(samples.size()) +
                            " is not finite");

  Workspace& w = *workspace_;
  w.prepare(samples);
  const std::size_t n = samples.size();
  const double centre = 0.5 * static_cast<double>(n - 1);
  count = std::min(count, n);
  std::vector<double> u;                          // the frequencies found, in radians per sample
  std::vector<std::complex<double>> projections;  // <e_j, z>
  std::vector<double> cholesky;  // L, row-major, of the Gram matrix G_ij = <e_i, e_j> = L L^T (real: chi is symmetric)
  std::vector<std::complex<double>> amplitude;
  for (std::size_t found = 0; found < count; ++found) {
    const Workspace::Peak peak = w.strongest_frequency();
    const double next = peak.u;
    // The new row of G and of its Cholesky factor L (G = L L^T); a pivot below 1e-20 (the new exponential's
    // component orthogonal to the earlier ones below 1e-10 of its norm) ends the search.
    const std::size_t size = found + 1;
    std::vector<double> row(size);
    for (std::size_t j = 0; j < found; ++j) {
      w.exponentials.set(next - u[j], n);
      row[j] = window_transform(w.exponentials, w.window) / w.window_sum;
    }
    row[found] = 1.0;
    std::vector<double> l_row(size);
    double pivot = row[found];
    for (std::size_t j = 0; j < found; ++j) {
      double sum = row[j];
      for (std::size_t i = 0; i < j; ++i) sum -= l_row[i] * cholesky[j * count + i];
      l_row[j] = sum / cholesky[j * count + j];
      pivot -= l_row[j] * l_row[j];
    }
    if (!(pivot > 1e-20)) break;
    l_row[found] = std::sqrt(pivot);
    cholesky.resize(size * count);
    std::copy(l_row.begin(), l_row.end(), cholesky.begin() + static_cast<std::ptrdiff_t>(found * count));
    u.push_back(next);
    if (found == 0) {  // the residual is still the signal
      projections.push_back(peak.transform / w.window_sum);
    } else {
      w.exponentials.set(next, n);
      projections.push_back(transform(w.exponentials, w.signal_re, w.signal_im) / w.window_sum);
    }
    // Solve L L^T a = b.
    amplitude.assign(size, {0.0, 0.0});
    for (std::size_t i = 0; i < size; ++i) {
      std::complex<double> sum = projections[i];
      for (std::size_t j = 0; j < i; ++j) sum -= cholesky[i * count + j] * amplitude[j];
      amplitude[i] = sum / cholesky[i * count + i];
    }
    for (std::size_t i = size; i-- > 0;) {
      std::complex<double> sum = amplitude[i];
      for (std::size_t j = i + 1; j < size; ++j) sum -= cholesky[j * count + i] * amplitude[j];
      amplitude[i] = sum / cholesky[i * count + i];
    }
    if (size == count) break;
    // The residual chi (z - sum_j a_j e_j), e_j = exp(i u_j x_k), the conjugate of what Exponentials hands out.
    w.residual_re = w.signal_re;
    w.residual_im = w.signal_im;
    for (std::size_t j = 0; j < size; ++j) {
      w.exponentials.set(u[j], n);
      const double ar = amplitude[j].real(), ai = amplitude[j].imag();
      const double *er = w.exponentials.re(), *ei = w.exponentials.im();
      for (std::size_t k = 0; k < n; ++k) {
        // a exp(+i u x) = (ar + i ai)(er - i ei)
        w.residual_re[k] -= w.window[k] * (ar * er[k] + ai * ei[k]);
        w.residual_im[k] -= w.window[k] * (ai * er[k] - ar * ei[k]);
      }
    }
  }
  std::vector<FrequencyTerm> result(u.size());
  for (std::size_t j = 0; j < u.size(); ++j)
    result[j] = {wrap(u[j]) / tau, amplitude[j] * std::polar(1.0, -u[j] * centre)};
  std::stable_sort(result.begin(), result.end(), [](const FrequencyTerm& a, const FrequencyTerm& b) {
    return std::abs(a.amplitude) > std::abs(b.amplitude);
  });
  return result;
}

double FrequencyAnalysis::fundamental_frequency(std::span<const std::complex<double>> samples, double tau) {
  return terms(samples, tau, 1).front().frequency;
}

double diffusion_index(std::span<const double> first, std::span<const double> second) {
  if (first.empty() || first.size() != second.size())
    throw InvalidArgument("diffusion index: " + std::to_string(first.size()) + " frequencies in the first window and " +
                          std::to_string(second.size()) + " in the second; the same number, at least 1, needed");
  double change = 0.0, first_norm = 0.0, second_norm = 0.0;
  for (std::size_t j = 0; j < first.size(); ++j) {
    if (!std::isfinite(first[j]) || !std::isfinite(second[j]))
      throw InvalidArgument("diffusion index: frequency " + std::to_string(j) + " is not finite (" +
                            std::to_string(first[j]) + " and " + std::to_string(second[j]) + ")");
    change += (second[j] - first[j]) * (second[j] - first[j]);
    first_norm += first[j] * first[j];
    second_norm += second[j] * second[j];
  }
  const double scale = std::sqrt(std::max(first_norm, second_norm));
  const double relative = scale == 0.0 ? 0.0 : std::sqrt(change) / scale;
  return std::log10(std::max(relative, std::numeric_limits<double>::epsilon()));
}

}  // namespace nonsep
