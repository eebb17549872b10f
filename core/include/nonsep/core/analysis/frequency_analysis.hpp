#pragma once
// Frequency analysis of a sampled orbit by NAFF, Laskar's Numerical Analysis of Fundamental Frequencies (J. Laskar,
// C. Froeschle and A. Celletti, Physica D 56, 253 (1992); J. Laskar, Physica D 67, 257 (1993)): the strongest
// terms a_j exp(i nu_j t) of a complex signal z(t), e.g. z = q_j + i p_j of one degree of freedom, sampled at
//   z_k = z(t0 + k tau),   k = 0 .. N-1,   T = (N-1) tau.
// The frequency map analysis of an orbit compares the fundamental frequencies nu of two windows, the first and the
// second half of a run: on a torus nu is the same in both up to the method's error, in a chaotic zone it drifts;
// diffusion_index() turns the two into one number.
//
// Method. With the window chi_k = 1 - cos(2 pi k / (N-1)) (Laskar's window of order 1, 1 + cos(2 pi t / T) at the
// centred times t = s_k = (k - (N-1)/2) tau in [-T/2, T/2], mean 1; the symmetric Hann window times 2, a factor the
// normalisation removes anyway), the windowed transform is
//   phi(omega) = sum_k chi_k z_k exp(-i omega s_k) / sum_k chi_k,
// normalised so that a pure term a exp(i nu t) gives |phi(nu)| = |a|. Each term is found in the residual r of the
// signal after the earlier ones (r = z at first):
//   1. first guess: the largest |FFT| bin of chi r (zero-padded to the next power of two, so the grid is at most
//      one bin 2 pi / (N tau) apart), refined by a parabola through the logarithms of the three bins at the peak;
//   2. the maximum of |phi(omega)| to full double precision, within one grid step either side of the peak: the
//      root of d|phi|^2/domega = 2 Re(conj(phi) phi') by Newton's method (phi, phi', phi'' in one pass over the
//      samples; the exponentials from a table of 2 sqrt(N) sines and cosines, exact to a few ulp, not a rotation
//      that accumulates round-off), safeguarded by bisection when a step leaves the bracket or the curvature has
//      the wrong sign;
//   3. the amplitudes of all terms found so far by projection of z on their exponentials in the windowed inner
//      product <f, g> = sum_k chi_k conj(f_k) g_k / sum_k chi_k. The exponentials are not orthogonal over a finite
//      window: the projection is Gram-Schmidt's, done on the Gram matrix G_ij = <e_i, e_j> (its Cholesky
//      factorisation), and the new residual is r = z - sum_j a_j e_j.
// A term whose exponential is already (to 1e-10 of its norm) in the span of the earlier ones cannot be separated
// from them and ends the search: fewer than the asked number of terms come back (a zero signal gives one term,
// frequency 0 and amplitude 0).
//
// Accuracy. For a quasi-periodic signal the error of a frequency with this window falls like T^-4 (Laskar 1993:
// T^-(2p+2) for the window of order p; without a window, T^-2), the leakage of the other terms through the window's
// side lobes, until round-off. Measured (tests/core/test_frequency_analysis.cpp): nu = 1 beside a term 0.3 at 1.05,
// errors from 1.05e-5 at T = 100 periods to 1.5e-10 at 1600, fitted exponent -4.01, one ulp of nu at 51200 periods;
// three terms over 1000 periods, frequencies within 2.5e-14 relative and amplitudes within 8e-11.
// A frequency is known modulo the sampling frequency 2 pi / tau: the result lies in [-pi/tau, pi/tau).
//
// Conventions. Frequencies are angular, in radians per unit time, signed: nu > 0 turns counter-clockwise in the
// complex plane (q + i p of a harmonic oscillator with H = (q^2 + p^2)/2 turns clockwise: nu = -1). Amplitudes refer
// to the first sample, z_k ~ sum_j a_j exp(i nu_j k tau). Terms come strongest first (by |a_j|).
//
// Cost. Per term one FFT of the padded length M (about half the time of a fundamental frequency) and two or three
// passes of some 20 flops per sample, plus the projection, O(N m^2) for m terms. The FrequencyAnalysis object keeps
// the FFT's tables for each length it has seen and its buffers: keep one object per thread and reuse it. One
// fundamental frequency of 2^14 samples takes some 0.35 ms on one core (bench/frequency_analysis.cpp measures it;
// docs/dynamics.md has the figures).
//
// Errors: InvalidArgument for fewer than minimum_samples samples, a non-finite sample, tau not finite and
// positive, and a request for zero terms.
#include <complex>
#include <cstddef>
#include <memory>
#include <span>
#include <vector>

namespace nonsep {

// One term a exp(i nu k tau) of the signal.
struct FrequencyTerm {
  double frequency = 0.0;            // nu, radians per unit time, signed
  std::complex<double> amplitude{};  // a, at the first sample
};

class FrequencyAnalysis {
 public:
  // The window's main lobe is 4 bins wide: fewer samples cannot tell a term from the window's side lobes.
  static constexpr std::size_t minimum_samples = 16;

  FrequencyAnalysis();
  ~FrequencyAnalysis();
  FrequencyAnalysis(FrequencyAnalysis&&) noexcept;  // a moved-from object may only be assigned to or destroyed
  FrequencyAnalysis& operator=(FrequencyAnalysis&&) noexcept;

  // The (at most) `count` strongest terms of z_k = samples[k], sampled every `tau`, strongest first.
  std::vector<FrequencyTerm> terms(std::span<const std::complex<double>> samples, double tau, std::size_t count);

  // The frequency of the strongest term: terms(samples, tau, 1)[0].frequency.
  double fundamental_frequency(std::span<const std::complex<double>> samples, double tau);

 private:
  struct Workspace;
  std::unique_ptr<Workspace> workspace_;
};

// Laskar's diffusion index of an orbit from the fundamental frequencies of two windows (one per degree of
// freedom, the same number in each):
//   log10(|nu_second - nu_first| / max(|nu_first|, |nu_second|))
// with Euclidean norms over the degrees of freedom. On a torus it is the method's error (-14.4 for a two-frequency
// torus over 2000 periods in the tests); a frequency that drifts by a fraction d over the run gives about
// log10(d/2), as the halves see their mean frequencies. The relative change is floored at the double precision epsilon
// (an index of -15.65 for identical frequencies, 0 / 0 included), so that the index is always finite. InvalidArgument
// for spans of different or zero sizes and for non-finite frequencies.
double diffusion_index(std::span<const double> first, std::span<const double> second);

}  // namespace nonsep
