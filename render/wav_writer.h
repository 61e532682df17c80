// A sound file written through libsndfile that appears whole on commit() or not at all: a WAV
// (the same bytes for the same samples: no time stamp in any chunk), or a FLAC or Ogg Vorbis file
// when the caller asks for one — hamiltone-render by -o's extension (fileTypeOf).
#pragma once

#include <sndfile.h>

#include <cstddef>
#include <string>
#include <vector>

#include "atomic_file.h"

namespace hamiltone::cli {

enum class SampleFormat { pcm16, pcm24, float32 };  // Ogg Vorbis, lossy, has none of its own

enum class FileType { wav, flac, ogg };

constexpr int kOggMaxRate = 200000;  // Hz: the highest libvorbis's encoder setup takes

// The type the extension of `path` names, in any case: .wav, .flac, .ogg. UsageError naming `flag`,
// the path and its extension, and listing the valid ones, for any other extension or none.
FileType fileTypeOf(const std::string& path, const std::string& flag);

class WavWriter {
 public:
  // Creates the temporary beside `path` now (see AtomicFile), so a bad path fails before any
  // rendering: UsageError naming `flag` for an empty path, a directory, a device or an
  // unwritable directory; std::invalid_argument for a sample rate <= 0 (or above kOggMaxRate for
  // Ogg), channels not 1 or 2, or FLAC in float32 (FLAC holds integers); std::runtime_error naming
  // the path if libsndfile refuses the format.
  // `keepOthers`: as AtomicFile's (a recording).
  WavWriter(std::string path, const std::string& flag, int sampleRate, int channels,
            SampleFormat format, FileType type = FileType::wav, bool keepOthers = false);
  ~WavWriter();  // closes and removes the temporary unless committed
  WavWriter(const WavWriter&) = delete;
  WavWriter& operator=(const WavWriter&) = delete;

  // Appends `frames` interleaved frames. Each sample is sanitised first — NaN and ±Inf become 0,
  // the rest is clamped to [-1, 1] — so one bad sample cannot wrap around in PCM or put a NaN
  // or a value past full scale in a float file. Copies through a buffer sized once in the
  // constructor, so a call allocates nothing.
  // Throws std::runtime_error naming the path and the write's error ("No space left on device"),
  // or libsndfile's message; the frames written before the failure are kept, and framesWritten()
  // counts them.
  void write(const float* interleaved, std::size_t frames);
  // Writes the encoder's last blocks and the header, closes and renames onto the path; throws
  // std::runtime_error naming the path and the error if any write of the file failed or fell
  // short, even one libsndfile took as done (its FLAC and Vorbis encoders do).
  // After a failed write() a WAV is cut to framesWritten() whole frames first, so what appears
  // is a valid WAV of what was written before the failure; a compressed file cannot be cut, so
  // then commit() throws and nothing appears.
  void commit();
  // Closes and removes the temporary now (AtomicFile::discard); nothing is written after it.
  void discard();

  std::size_t framesWritten() const { return written_; }

  const std::string& path() const { return path_; }
  // Where commit() put the file: the path, or beside it (keepOthers).
  const std::string& publishedPath() const { return file_.path(); }
  bool movedAside() const { return file_.movedAside(); }
  int sampleRate() const { return sampleRate_; }
  int channels() const { return channels_; }

 private:
  std::string path_;
  int sampleRate_, channels_;
  FileType type_;
  AtomicFile file_;
  SNDFILE* sound_ = nullptr;  // writes through the temporary's descriptor, by the calls below
  int descriptor_ = -1;       // the temporary's
  int ioError_ = 0;           // errno of the first write that failed or fell short; 0: none
  static sf_count_t ioLength(void* self);
  static sf_count_t ioSeek(sf_count_t offset, int whence, void* self);
  static sf_count_t ioRead(void* to, sf_count_t bytes, void* self);
  static sf_count_t ioWrite(const void* from, sf_count_t bytes, void* self);
  static sf_count_t ioTell(void* self);
  // "writing PATH failed: " and the write's error, or libsndfile's message if no write failed.
  std::string failure(const char* libsndfileSays) const;
  std::vector<float> chunk_;  // sanitised samples on their way to libsndfile
  std::size_t written_ = 0;   // whole frames libsndfile took
  bool failed_ = false;       // a write() failed: the file may end in part of a frame
};

}  // namespace hamiltone::cli
