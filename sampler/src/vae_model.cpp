#include "drapegen/sampler/vae_model.hpp"

#include "builtin_model.hpp"

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <numbers>
#include <span>
#include <vector>

namespace drapegen::sampler {
namespace {

constexpr char kMagic[8] = {'D', 'G', 'V', 'A', 'E', '\0', '\0', '\1'};
constexpr std::uint32_t kGaussianVersion = 1;  // Gaussian observation, no observation code
constexpr std::uint32_t kVersion = 2;          // observation code in the header, Student-t degrees of freedom
constexpr std::uint32_t kActivationElu = 1;

std::uint64_t fnv1a(const unsigned char* data, std::size_t size) {
  std::uint64_t h = 0xcbf29ce484222325ULL;
  for (std::size_t i = 0; i < size; ++i) {
    h ^= data[i];
    h *= 0x100000001b3ULL;
  }
  return h;
}

void elu_in_place(Eigen::MatrixXd& m) {
  m = m.unaryExpr([](double v) { return v > 0.0 ? v : std::expm1(v); });
}

Eigen::MatrixXd apply(const DenseLayer& layer, const Eigen::MatrixXd& x) {
  Eigen::MatrixXd y = layer.weight * x;
  y.colwise() += layer.bias;
  return y;
}

/// Reads little-endian values from a byte buffer, remembering whether it ran past the end.
class Reader {
 public:
  Reader(const std::vector<unsigned char>& bytes, std::size_t end) : bytes_(bytes), end_(end) {}
  bool truncated() const { return truncated_; }
  std::size_t position() const { return pos_; }

  void skip(std::size_t n) {
    if (pos_ + n > end_) {
      truncated_ = true;
      pos_ = end_;
    } else {
      pos_ += n;
    }
  }
  std::uint32_t u32() {
    unsigned char b[4] = {};
    take(b, 4);
    return std::uint32_t(b[0]) | std::uint32_t(b[1]) << 8 | std::uint32_t(b[2]) << 16 | std::uint32_t(b[3]) << 24;
  }
  std::uint64_t u64() {
    unsigned char b[8] = {};
    take(b, 8);
    std::uint64_t v = 0;
    for (int i = 7; i >= 0; --i) v = (v << 8) | b[i];
    return v;
  }
  double f64() {
    const std::uint64_t bits = u64();
    double v;
    std::memcpy(&v, &bits, sizeof v);
    return v;
  }
  void features(Features& out) {
    for (double& v : out) v = f64();
  }
  DenseLayer dense(int in, int out) {
    DenseLayer layer{Eigen::MatrixXd(out, in), Eigen::VectorXd(out)};
    for (int r = 0; r < out; ++r) {
      for (int c = 0; c < in; ++c) layer.weight(r, c) = f64();
    }
    for (int r = 0; r < out; ++r) layer.bias(r) = f64();
    return layer;
  }

 private:
  void take(unsigned char* out, std::size_t n) {
    if (pos_ + n > end_) {
      truncated_ = true;
      pos_ = end_;
      return;
    }
    std::memcpy(out, bytes_.data() + pos_, n);
    pos_ += n;
  }
  const std::vector<unsigned char>& bytes_;
  std::size_t end_;
  std::size_t pos_ = 0;
  bool truncated_ = false;
};

class Writer {
 public:
  void u32(std::uint32_t v) {
    for (int i = 0; i < 4; ++i) bytes.push_back(static_cast<unsigned char>(v >> (8 * i)));
  }
  void u64(std::uint64_t v) {
    for (int i = 0; i < 8; ++i) bytes.push_back(static_cast<unsigned char>(v >> (8 * i)));
  }
  void f64(double v) {
    std::uint64_t bits;
    std::memcpy(&bits, &v, sizeof v);
    u64(bits);
  }
  void features(const Features& f) {
    for (double v : f) f64(v);
  }
  void dense(const DenseLayer& layer) {
    for (int r = 0; r < layer.weight.rows(); ++r) {
      for (int c = 0; c < layer.weight.cols(); ++c) f64(layer.weight(r, c));
    }
    for (int r = 0; r < layer.bias.size(); ++r) f64(layer.bias(r));
  }
  std::vector<unsigned char> bytes;
};

bool shaped(const DenseLayer& layer, int in, int out) {
  return layer.weight.rows() == out && layer.weight.cols() == in && layer.bias.size() == out &&
         layer.weight.allFinite() && layer.bias.allFinite();
}

/// What validate() says of a layer (or the encoder's heads) that fails shaped().
sim::Error malformed(const std::string& what) {
  return sim::Error{what + " is malformed (wrong shape or non-finite values)"};
}

}  // namespace

sim::Status VaeModel::validate() const {
  const int h = static_cast<int>(hidden.size());
  if (latent_dim < 1 || latent_dim > 1024) return sim::Error{"latent dimension must be 1..1024"};
  if (h < 1 || h > 16) return sim::Error{"the model needs 1..16 hidden layers"};
  for (int w : hidden) {
    if (w < 1 || w > 8192) return sim::Error{"hidden layer widths must be 1..8192"};
  }
  for (int i = 0; i < kFeatureCount; ++i) {
    if (!std::isfinite(feature_mean[i]) || !(feature_std[i] > 0.0) || !std::isfinite(feature_std[i]) ||
        !std::isfinite(range_low[i]) || !std::isfinite(range_high[i]) || !(range_low[i] <= range_high[i]) ||
        !std::isfinite(log_sigma[i])) {
      return sim::Error{std::string("normalisation or range of feature ") + kFeatureNames[i] +
                        " is not finite or not ordered (std > 0, low <= high)"};
    }
  }
  if (observation != Observation::gaussian && observation != Observation::student_t) {
    return sim::Error{"unknown observation model"};
  }
  if (observation == Observation::student_t) {
    for (int i = 0; i < kFeatureCount; ++i) {
      if (!(degrees_of_freedom[i] > 1.0) || !std::isfinite(degrees_of_freedom[i])) {
        return sim::Error{std::string("Student-t degrees of freedom of feature ") + kFeatureNames[i] +
                          " must be finite and > 1"};
      }
    }
  }
  if (static_cast<int>(encoder.size()) != h || static_cast<int>(decoder.size()) != h + 1) {
    return sim::Error{"layer counts do not match the hidden widths"};
  }
  int in = kFeatureCount;
  for (int i = 0; i < h; ++i) {
    if (!shaped(encoder[i], in, hidden[i])) return malformed("encoder layer " + std::to_string(i));
    in = hidden[i];
  }
  if (!shaped(encoder_mu, in, latent_dim) || !shaped(encoder_logvar, in, latent_dim)) {
    return malformed("encoder heads");
  }
  in = latent_dim;
  for (int i = 0; i <= h; ++i) {
    const int out = i < h ? hidden[h - 1 - i] : kFeatureCount;
    if (!shaped(decoder[i], in, out)) return malformed("decoder layer " + std::to_string(i));
    in = out;
  }
  return {};
}

double VaeModel::log_observation(const Eigen::VectorXd& standardised, const Eigen::VectorXd& mean) const {
  double total = 0.0;
  for (int i = 0; i < kFeatureCount; ++i) {
    const double r = (standardised(i) - mean(i)) * std::exp(-log_sigma[i]);
    if (observation == Observation::gaussian) {
      total += -0.5 * r * r - log_sigma[i] - 0.5 * std::log(2.0 * std::numbers::pi);
    } else {
      const double nu = degrees_of_freedom[i];
      total += std::lgamma(0.5 * (nu + 1.0)) - std::lgamma(0.5 * nu) - 0.5 * std::log(nu * std::numbers::pi) -
               log_sigma[i] - 0.5 * (nu + 1.0) * std::log1p(r * r / nu);
    }
  }
  return total;
}

Eigen::MatrixXd VaeModel::decode_standardised(const Eigen::MatrixXd& latents) const {
  Eigen::MatrixXd x = latents;
  for (std::size_t i = 0; i < decoder.size(); ++i) {
    x = apply(decoder[i], x);
    if (i + 1 < decoder.size()) elu_in_place(x);
  }
  return x;
}

Eigen::MatrixXd VaeModel::decode(const Eigen::MatrixXd& latents) const {
  Eigen::MatrixXd s = decode_standardised(latents);
  for (int i = 0; i < kFeatureCount; ++i) s.row(i) = s.row(i).array() * feature_std[i] + feature_mean[i];
  return s;
}

void VaeModel::encode_standardised(const Eigen::MatrixXd& standardised, Eigen::MatrixXd& mu,
                                   Eigen::MatrixXd& logvar) const {
  Eigen::MatrixXd x = standardised;
  for (const DenseLayer& layer : encoder) {
    x = apply(layer, x);
    elu_in_place(x);
  }
  mu = apply(encoder_mu, x);
  logvar = apply(encoder_logvar, x);
}

sim::Expected<VaeModel> load_vae_model(const std::string& path) {
  const std::string where = "model file '" + path + "'";
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) return sim::Error{where + " is a directory"};
  // Read whole below: a device or a pipe (/dev/zero) would never end, a huge file would fill the memory first.
  const auto status = std::filesystem::status(path, ec);
  if (std::filesystem::exists(status) && !std::filesystem::is_regular_file(status)) {
    return sim::Error{where + " is not a regular file"};
  }
  constexpr std::uintmax_t kMaxModelBytes = std::uintmax_t{1} << 30;  // VAE-1, the largest of Table 1: about 44 MB
  if (const std::uintmax_t size = std::filesystem::file_size(path, ec); !ec && size > kMaxModelBytes) {
    return sim::Error{where + " is " + std::to_string(size) + " bytes, larger than any model (1 GiB at most)"};
  }
  std::ifstream in(path, std::ios::binary);
  if (!in) return sim::Error{"cannot open " + where};
  std::vector<unsigned char> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (in.bad()) return sim::Error{"cannot read " + where};
  return parse_vae_model(bytes, where);
}

sim::Expected<VaeModel> builtin_vae_model() {
  const std::span<const unsigned char> bytes = detail::builtin_model_bytes();
  return parse_vae_model(std::vector<unsigned char>(bytes.begin(), bytes.end()), "the built-in model");
}

sim::Expected<VaeModel> parse_vae_model(const std::vector<unsigned char>& bytes, const std::string& where) {
  if (bytes.size() < sizeof kMagic || std::memcmp(bytes.data(), kMagic, sizeof kMagic) != 0) {
    return sim::Error{where + " is not a drapegen VAE model (bad magic bytes)"};
  }
  if (bytes.size() < sizeof kMagic + 8) return sim::Error{where + " is truncated (no checksum)"};
  const std::size_t body_end = bytes.size() - 8;
  Reader r(bytes, body_end);
  r.skip(sizeof kMagic);
  const std::uint32_t version = r.u32();
  if (r.truncated()) return sim::Error{where + " is truncated in its header"};
  if (version != kGaussianVersion && version != kVersion) {
    return sim::Error{where + " has format version " + std::to_string(version) + "; this program reads versions " +
                      std::to_string(kGaussianVersion) + " and " + std::to_string(kVersion)};
  }
  const std::uint32_t dim = r.u32(), latent = r.u32(), layers = r.u32(), activation = r.u32();
  const std::uint32_t observation = version == kGaussianVersion ? 0 : r.u32();
  if (r.truncated()) return sim::Error{where + " is truncated in its header"};
  if (dim != kFeatureCount) return sim::Error{where + " has " + std::to_string(dim) + " features, expected 6"};
  if (latent < 1 || latent > 1024 || layers < 1 || layers > 16) {
    return sim::Error{where + " has an implausible latent dimension or layer count (corrupt header?)"};
  }
  if (activation != kActivationElu) return sim::Error{where + " uses an unknown activation code"};
  if (observation > 1) return sim::Error{where + " uses an unknown observation model code"};
  VaeModel m;
  m.observation = static_cast<Observation>(observation);
  m.latent_dim = static_cast<int>(latent);
  for (std::uint32_t i = 0; i < layers; ++i) {
    const std::uint32_t w = r.u32();
    if (w < 1 || w > 8192) return sim::Error{where + " has an implausible layer width (corrupt header?)"};
    m.hidden.push_back(static_cast<int>(w));
  }
  if (r.truncated()) return sim::Error{where + " is truncated in its header"};
  // The size the header implies, checked before reading any array.
  std::uint64_t reals = (m.observation == Observation::student_t ? 6ULL : 5ULL) * kFeatureCount;
  std::uint64_t in_w = kFeatureCount;
  for (int w : m.hidden) reals += (in_w + 1) * w, in_w = w;
  reals += 2 * (in_w + 1) * latent;
  in_w = latent;
  for (int i = static_cast<int>(layers) - 1; i >= 0; --i) reals += (in_w + 1) * m.hidden[i], in_w = m.hidden[i];
  reals += (in_w + 1) * kFeatureCount;
  const std::uint64_t expected = r.position() + 8 * reals + 8;
  if (bytes.size() < expected) {
    return sim::Error{where + " is truncated: " + std::to_string(bytes.size()) + " bytes, the header implies " +
                      std::to_string(expected)};
  }
  if (bytes.size() > expected) {
    return sim::Error{where + " has " + std::to_string(bytes.size() - expected) + " unexpected trailing bytes"};
  }
  std::uint64_t stored = 0;
  for (int i = 7; i >= 0; --i) stored = (stored << 8) | bytes[body_end + i];
  if (fnv1a(bytes.data(), body_end) != stored) {
    return sim::Error{where + " is corrupt (checksum mismatch)"};
  }
  r.features(m.feature_mean);
  r.features(m.feature_std);
  r.features(m.range_low);
  r.features(m.range_high);
  r.features(m.log_sigma);
  if (m.observation == Observation::student_t) r.features(m.degrees_of_freedom);
  int in_width = kFeatureCount;
  for (int w : m.hidden) {
    m.encoder.push_back(r.dense(in_width, w));
    in_width = w;
  }
  m.encoder_mu = r.dense(in_width, m.latent_dim);
  m.encoder_logvar = r.dense(in_width, m.latent_dim);
  in_width = m.latent_dim;
  for (int i = static_cast<int>(layers) - 1; i >= 0; --i) {
    m.decoder.push_back(r.dense(in_width, m.hidden[i]));
    in_width = m.hidden[i];
  }
  m.decoder.push_back(r.dense(in_width, kFeatureCount));
  if (r.truncated() || r.position() != body_end) return sim::Error{where + " does not match its header"};
  if (sim::Status s = m.validate(); !s) return sim::Error{where + ": " + s.error().message};
  return m;
}

sim::Status save_vae_model(const VaeModel& model, const std::string& path) {
  if (sim::Status s = model.validate(); !s) return s;
  Writer w;
  w.bytes.assign(kMagic, kMagic + sizeof kMagic);
  const bool gaussian = model.observation == Observation::gaussian;
  w.u32(gaussian ? kGaussianVersion : kVersion);
  w.u32(kFeatureCount);
  w.u32(static_cast<std::uint32_t>(model.latent_dim));
  w.u32(static_cast<std::uint32_t>(model.hidden.size()));
  w.u32(kActivationElu);
  if (!gaussian) w.u32(static_cast<std::uint32_t>(model.observation));
  for (int h : model.hidden) w.u32(static_cast<std::uint32_t>(h));
  w.features(model.feature_mean);
  w.features(model.feature_std);
  w.features(model.range_low);
  w.features(model.range_high);
  w.features(model.log_sigma);
  if (!gaussian) w.features(model.degrees_of_freedom);
  for (const DenseLayer& l : model.encoder) w.dense(l);
  w.dense(model.encoder_mu);
  w.dense(model.encoder_logvar);
  for (const DenseLayer& l : model.decoder) w.dense(l);
  w.u64(fnv1a(w.bytes.data(), w.bytes.size()));
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  if (!out) return sim::Error{"cannot create model file '" + path + "'"};
  out.write(reinterpret_cast<const char*>(w.bytes.data()), static_cast<std::streamsize>(w.bytes.size()));
  out.close();
  if (!out) return sim::Error{"cannot write model file '" + path + "'"};
  return {};
}

std::string default_model_path() { return DRAPEGEN_SAMPLER_DEFAULT_MODEL; }

std::string default_fabric_data_path() { return DRAPEGEN_SAMPLER_DEFAULT_DATA; }

}  // namespace drapegen::sampler
