// libsndfile writes through the descriptor of an AtomicFile's temporary, so AtomicFile alone
// decides whether the file appears: commit() renames it, the destructor and the signals that end
// the program remove it. It writes through our own calls (virtual I/O), which keep the first
// error of any write: its FLAC and Vorbis encoders report success after a short write (a disk
// that fills while the file is closed gave a truncated file and exit 0), so the writer cannot
// trust libsndfile's own status.
#include "wav_writer.h"

#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <stdexcept>

#include "usage_error.h"

namespace hamiltone::cli {

namespace {

// Frames sanitised per libsndfile call: 32 KiB of stereo floats, allocated once.
constexpr std::size_t kChunkFrames = 4096;

// Checked in the member initialisers, before AtomicFile creates the temporary.
int checkedSampleRate(int sampleRate) {
  if (sampleRate <= 0)
    throw std::invalid_argument("WavWriter: sample rate " + std::to_string(sampleRate) +
                                " Hz; expected > 0");
  return sampleRate;
}

int checkedChannels(int channels) {
  if (channels != 1 && channels != 2)
    throw std::invalid_argument("WavWriter: " + std::to_string(channels) +
                                " channels; expected 1 or 2");
  return channels;
}

int container(FileType type) {
  switch (type) {
    case FileType::wav:
      return SF_FORMAT_WAV;
    case FileType::flac:
      return SF_FORMAT_FLAC;
    case FileType::ogg:
      return SF_FORMAT_OGG;
  }
  throw std::invalid_argument("WavWriter: unknown file type");
}

// Checked in the member initialisers, with the rate and the channels.
FileType checkedType(FileType type, SampleFormat format, int sampleRate) {
  if (type == FileType::flac && format == SampleFormat::float32)
    throw std::invalid_argument("FLAC holds integer samples: pcm16 or pcm24, not float32");
  if (type == FileType::ogg && sampleRate > kOggMaxRate)
    throw std::invalid_argument("Ogg Vorbis holds rates up to " + std::to_string(kOggMaxRate) +
                                " Hz, not " + std::to_string(sampleRate));
  return type;
}

int subformat(SampleFormat format) {
  switch (format) {
    case SampleFormat::pcm16:
      return SF_FORMAT_PCM_16;
    case SampleFormat::pcm24:
      return SF_FORMAT_PCM_24;
    case SampleFormat::float32:
      return SF_FORMAT_FLOAT;
  }
  throw std::invalid_argument("WavWriter: unknown sample format");
}

float sanitised(float x) { return std::isfinite(x) ? std::clamp(x, -1.0f, 1.0f) : 0.0f; }

}  // namespace

// libsndfile's virtual I/O on the temporary's descriptor, as sf_open_fd would use it, except that
// a failed or short write is kept in ioError_.
sf_count_t WavWriter::ioLength(void* self) {
  struct stat st {};
  return ::fstat(static_cast<WavWriter*>(self)->descriptor_, &st) == 0 ? st.st_size : -1;
}

sf_count_t WavWriter::ioSeek(sf_count_t offset, int whence, void* self) {
  return ::lseek(static_cast<WavWriter*>(self)->descriptor_, offset, whence);
}

sf_count_t WavWriter::ioRead(void* to, sf_count_t bytes, void* self) {
  const int fd = static_cast<WavWriter*>(self)->descriptor_;
  sf_count_t done = 0;
  while (done < bytes) {
    const ssize_t n = ::read(fd, static_cast<char*>(to) + done, static_cast<size_t>(bytes - done));
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) break;
    done += n;
  }
  return done;
}

sf_count_t WavWriter::ioWrite(const void* from, sf_count_t bytes, void* self) {
  WavWriter& writer = *static_cast<WavWriter*>(self);
  sf_count_t done = 0;
  while (done < bytes) {
    const ssize_t n = ::write(writer.descriptor_, static_cast<const char*>(from) + done,
                              static_cast<size_t>(bytes - done));
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) {
      if (writer.ioError_ == 0) writer.ioError_ = n < 0 ? errno : EIO;
      break;
    }
    done += n;
  }
  return done;
}

sf_count_t WavWriter::ioTell(void* self) {
  return ::lseek(static_cast<WavWriter*>(self)->descriptor_, 0, SEEK_CUR);
}

std::string WavWriter::failure(const char* libsndfileSays) const {
  return "writing " + path_ + " failed: " +
         (ioError_ != 0 ? std::string(std::strerror(ioError_)) : std::string(libsndfileSays));
}

FileType fileTypeOf(const std::string& path, const std::string& flag) {
  std::string extension = std::filesystem::path(path).extension().string();
  for (char& c : extension) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  if (extension == ".wav") return FileType::wav;
  if (extension == ".flac") return FileType::flac;
  if (extension == ".ogg") return FileType::ogg;
  throw UsageError(
      flag + " " + path + ": " +
      (extension.empty() ? "no extension" : extension + " is not a format hamiltone can write") +
      "; the extension chooses the format: .wav, .flac or .ogg (Ogg Vorbis)");
}

WavWriter::WavWriter(std::string path, const std::string& flag, int sampleRate, int channels,
                     SampleFormat format, FileType type, bool keepOthers)
    : path_(std::move(path)),
      sampleRate_(checkedSampleRate(sampleRate)),
      channels_(checkedChannels(channels)),
      type_(checkedType(type, format, sampleRate)),
      file_(path_, flag, keepOthers) {
  SF_INFO info{};
  info.samplerate = sampleRate_;
  info.channels = channels_;
  info.format = container(type_) | (type_ == FileType::ogg ? SF_FORMAT_VORBIS : subformat(format));
  descriptor_ = fileno(file_.stream());
  SF_VIRTUAL_IO io{ioLength, ioSeek, ioRead, ioWrite, ioTell};
  sound_ = sf_open_virtual(&io, SFM_WRITE, &info, this);
  if (!sound_)
    throw std::runtime_error(
        "cannot write " + path_ + ": " +
        (ioError_ != 0 ? std::strerror(ioError_)
                       : std::string("libsndfile refuses the format: ") + sf_strerror(nullptr)));
  // With clipping on, libsndfile saturates +1.0 — it scales by 2^15 (2^23 for 24-bit), one
  // step past the largest code — instead of wrapping it to -1. (It then rounds down, 1.2.0
  // measured: an error below one step, where without clipping it rounds to nearest.)
  if (format != SampleFormat::float32 && type_ != FileType::ogg)
    sf_command(sound_, SFC_SET_CLIPPING, nullptr, SF_TRUE);
  // A float file would get a PEAK chunk stamped with the time of writing, so two renders of the
  // same input would differ in those bytes. The peaks are known to be within ±1 (sanitised), so
  // the chunk says nothing worth a non-reproducible file. Must precede the first write.
  if (format == SampleFormat::float32 && type_ == FileType::wav)
    sf_command(sound_, SFC_SET_ADD_PEAK_CHUNK, nullptr, SF_FALSE);
  chunk_.resize(kChunkFrames * static_cast<std::size_t>(channels_));
}

WavWriter::~WavWriter() { discard(); }

void WavWriter::discard() {
  if (sound_) sf_close(sound_);
  sound_ = nullptr;
  file_.discard();
}

void WavWriter::write(const float* interleaved, std::size_t frames) {
  if (!sound_) throw std::logic_error("WavWriter::write after commit: " + path_);
  while (frames > 0) {
    const std::size_t n = std::min(frames, kChunkFrames);
    const std::size_t samples = n * static_cast<std::size_t>(channels_);
    std::transform(interleaved, interleaved + samples, chunk_.begin(), sanitised);
    const sf_count_t done = sf_writef_float(sound_, chunk_.data(), static_cast<sf_count_t>(n));
    if (done != static_cast<sf_count_t>(n) || ioError_ != 0) {
      written_ += static_cast<std::size_t>(std::max<sf_count_t>(done, 0));
      failed_ = true;
      throw std::runtime_error(failure(sf_strerror(sound_)));
    }
    written_ += n;
    interleaved += samples;
    frames -= n;
  }
}

void WavWriter::commit() {
  if (!sound_) throw std::logic_error("WavWriter::commit twice: " + path_);
  if (failed_ && type_ != FileType::wav)
    throw std::runtime_error("writing " + path_ +
                             " failed: a compressed file cannot be kept up to "
                             "the error");
  if (failed_) {
    // Cut what a failed write left past the last whole frame: seeking the write position to
    // that frame puts the descriptor at the end of the data that is kept. libsndfile computes
    // the header's sizes from the file's length on close.
    const off_t end = sf_seek(sound_, static_cast<sf_count_t>(written_), SEEK_SET) < 0
                          ? -1
                          : ::lseek(descriptor_, 0, SEEK_CUR);
    if (end < 0 || ::ftruncate(descriptor_, end) != 0)
      throw std::runtime_error("writing " + path_ + " failed: cannot cut it to the " +
                               std::to_string(written_) + " frames written");
    ioError_ = 0;  // the data's failure is handled: what follows is the header's
  }
  const int error = sf_close(sound_);  // writes the encoder's last blocks and the final header
  sound_ = nullptr;
  if (error != SF_ERR_NO_ERROR || ioError_ != 0)
    throw std::runtime_error(failure(sf_error_number(error)));
  file_.commit();
}

}  // namespace hamiltone::cli
