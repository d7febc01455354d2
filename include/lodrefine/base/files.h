// What every reader and writer shares: the coordinate bound, telling formats apart by content,
// and atomic writes (a temporary beside the target, renamed over it), so no partial file is left.
#pragma once
#include <cstddef>
#include <new>
#include <set>
#include <string>
#include <vector>

#include "lodrefine/base/types.h"

namespace lodrefine {

// Georeferenced coordinates are at most a few 1e7 m (UTM northing); anything beyond 1e9 m is a
// broken file, and would overflow the integer grids of welding and hashing downstream. Every
// reader refuses such coordinates.
constexpr double kMaxCoordinate = 1e9;
// The finest CityJSON transform.scale accepted (m): coordinates within kMaxCoordinate then fit
// 64-bit integers when written back.
constexpr double kMinScale = 1e-9;

// What a file holds, judged by its first bytes (not its name): lets each reader say what a
// file given in the wrong place is, and lets commands that take several formats pick one.
enum class FileKind { Ply, Las, Xml, Json, Other };
FileKind sniff_file(const std::string& path);  // Other also for unreadable files (the reader reports)
FileKind sniff_head(const std::string& head);  // the same from a file's first (up to 64) bytes
// "a PLY point cloud", "a LAS/LAZ point cloud", "XML (a CityGML model?)", "JSON (a CityJSON
// model?)"; empty for Other.
std::string file_kind_text(FileKind kind);

// Prefix of every temporary file lodrefine writes (AtomicFile, crop's spill files): a kill -9
// leaves only files named so, which the batch scripts remove (and nothing else of the user's).
inline constexpr const char* kTempPrefix = ".lodrefine-tmp-";

// Creates a new, empty file `<dir>/.lodrefine-tmp-<random>` exclusively (O_EXCL|O_NOFOLLOW, so
// a file or symlink planted under a guessed name is never opened or followed) and returns its
// open descriptor (close-on-exec, mode 0644 less umask); `path` gets its name. Throws
// std::runtime_error "cannot write <for_path>: <reason>" when it cannot be created.
int create_temp_file(const std::string& dir, const std::string& for_path, std::string& path);

// A file written through a temporary beside the target (create_temp_file) and renamed over it
// on commit(); the temporary is removed if commit() is never reached (an exception; a kill -9
// leaves a ".lodrefine-tmp-*"). A symlink at `path` is replaced, never followed; a FIFO, device
// or socket there (or a link to one, /dev/stdout) is refused, never replaced. Constructing
// one is also the check that `path` can be written (its folder exists and is writable). For
// outputs written in pieces (streams); write_file_atomic for one piece.
class AtomicFile {
 public:
  explicit AtomicFile(const std::string& path);
  AtomicFile(const AtomicFile&) = delete;
  AtomicFile& operator=(const AtomicFile&) = delete;
  ~AtomicFile();
  void write(const char* data, std::size_t n);
  void write(const std::string& s) { write(s.data(), s.size()); }
  // Overwrites bytes already written at `offset` (a count only known at the end, in a header).
  void write_at(std::size_t offset, const std::string& s);
  void commit();
  [[noreturn]] void fail(const std::string& reason);  // discards, throws std::runtime_error

 private:
  void write_from(const char* data, std::size_t n, long long offset);  // offset < 0: at the end
  void discard();
  std::string path_, tmp_;
  int fd_ = -1;
  bool committed_ = false;
};

// The whole file as bytes (small inputs: a baseline, a gates file); throws InputError, one line
// naming `path`, for a directory or a file that cannot be read.
std::string read_file(const std::string& path);

// The input file this thread is reading, for the out-of-memory line. Memory running out while a
// model or cloud is read ends in the reader's catch, or in std::terminate when a destructor
// allocates while the bad_alloc unwinds (nlohmann::json's does), where only this is known; the
// name is kept in a fixed buffer, so reading it allocates nothing.
class ReadingFile {
 public:
  explicit ReadingFile(const std::string& path) noexcept;  // names `path` for this thread
  ~ReadingFile();                                          // names the file read before, if any
  ReadingFile(const ReadingFile&) = delete;
  ReadingFile& operator=(const ReadingFile&) = delete;
  static const char* name() noexcept;  // "" when no reader runs on this thread

 private:
  char previous_[512];
};

// read() under ReadingFile(path); memory running out in it throws OutOfMemory "<path>: out of
// memory reading the file" once what read() held is freed.
template <class Read>
auto read_naming_memory(const std::string& path, Read&& read) -> decltype(read()) {
  const ReadingFile reading(path);
  try {
    return read();
  } catch (const OutOfMemory&) {
    throw;
  } catch (const std::bad_alloc&) {
    throw OutOfMemory(path + ": out of memory reading the file");
  }
}

// Writes `content` to `path` atomically (temp file in the same directory + rename).
void write_file_atomic(const std::string& path, const std::string& content);
// Copies the regular file `from` to `to` atomically (same guarantees as write_file_atomic).
void copy_file_atomic(const std::string& from, const std::string& to);

// The files and folders one run writes below the output folder it was given. A folder below the
// root that is a symbolic link is refused (a planted `truth -> /elsewhere` would take the files
// where it points; the root itself is the user's and may be one), and what the run created is
// removed again unless keep() is reached: a run refused or failed half-way leaves no partial
// output, and nothing that was there before is ever removed. Write each file with AtomicFile (a
// link at a file is replaced, never followed). Paths `rel` are relative to the root, with no
// `..` (a programming error: std::logic_error).
class OutputTree {
 public:
  explicit OutputTree(std::string root) : root_(std::move(root)) {}
  OutputTree(const OutputTree&) = delete;
  OutputTree& operator=(const OutputTree&) = delete;
  ~OutputTree();  // removes what was created, newest first, unless kept

  // <root>/<rel> checked, nothing created: throws InputError "<path>: is a symbolic link; ..."
  // when it or a folder between it and the root is a link, "<path>: not a folder" when it is
  // anything else but a folder (or missing: fine). Returns the path.
  std::string check_folder(const std::string& rel = "") const;
  // Creates the root and the folders down to <root>/<rel> that are missing (each recorded),
  // after check_folder. Returns the path.
  std::string folder(const std::string& rel = "");
  // <root>/<rel>, a file this run is about to write in a folder made by folder(): recorded when
  // nothing is there yet. Returns the path.
  std::string file(const std::string& rel);
  const std::string& root() const { return root_; }
  void keep() { kept_ = true; }

 private:
  std::string root_;
  std::vector<std::string> created_;  // in creation order
  bool kept_ = false;
};

// Throws InputError "<path>: not a regular file ..." for devices, FIFOs, sockets and
// directories: reading /dev/zero or a pipe would not end (or not before gigabytes), and their
// size is unknown up front. Symlinks to regular files pass.
void require_regular_file(const std::string& path);

// True when `a` and `b` name the same file: the same device and inode when both exist (links,
// hard links and `./x` vs `x` all count), else the same real parent folder and name. Used to
// refuse an output that would overwrite an input, or another output, before reading anything.
bool same_file(const std::string& a, const std::string& b);

// A command's file option: its name ("--out") and path (empty: not given).
struct FileOption {
  const char* name;
  std::string path;
};
// Throws InputError "<path>: <output> is the <input> file; it would be overwritten", or "<path>:
// <output> is the <other output> file", when an output given is an input or another output
// (same_file). Called before anything is read.
void refuse_overwrites(const std::vector<FileOption>& inputs, const std::vector<FileOption>& outputs);

// A file (or folder) a command reads or is about to write, and what it is to the user: "the
// tile", "\"A\"'s cloud.ply".
struct RunFile {
  std::string what, path;
};
// Throws InputError "<input's path>: the <input's what> would be overwritten by <output's what>;
// give another --out" for the first of `outputs` written where one of `inputs` is read: a tile
// that lies in the output folder where a building's file goes, say. An input is where its links
// lead; an output is where it is written (its folders' links resolved; a link at the output
// itself is replaced, never followed, so the file it names is safe). Called before anything is
// written; `inputs` may hold an output another writes last (synth's tile).
void refuse_overwritten(const std::vector<RunFile>& inputs, const std::vector<RunFile>& outputs);

// Names for untrusted ids (CityObject ids, file stems) in file and folder names that make, the
// shell and every file system take as they are.
//
// safe_name(id) is `id` itself when it is already safe: only [A-Za-z0-9._-], not starting with
// '-' or '.', at most kMaxSafeName bytes (so safe_name(safe_name(x)) == safe_name(x)). Otherwise
// every other byte becomes '_', a leading '-'/'.' (or an empty id) gets a '_' in front, it is
// cut to 80 bytes and "--" plus 12 hex digits of a hash of the whole id are appended, so two ids
// that differ give different names (up to hash collisions and an id that is literally another
// one's hashed name: SafeNames resolves both within a set).
inline constexpr std::size_t kMaxSafeName = 100;
// An untrusted id for a message line: in double quotes, JSON-escaped (control characters as
// \u00XX, invalid UTF-8 as U+FFFD), so it can neither break the line nor the terminal; an id
// over kMaxShownId bytes is cut there (at a character's start) and shown as `"<first bytes>..."
// (<size> bytes)`, so a 100 kB id gives a line of a few hundred bytes. Every id quoted in a
// message goes through this.
inline constexpr std::size_t kMaxShownId = 80;
std::string shown_id(const std::string& id);
// An id at the head of a result line or a reason ("<id>: ...", "building <id>: ..."): as it is when
// it is a safe name (batch logs and the review page match those), else shown_id's form.
std::string line_id(const std::string& id);
// Untrusted text for a message line as it is, but for its control characters (C0, DEL, C1):
// \n, \r, \t or \xHH (a C1 character as its UTF-8 bytes), so a newline or an escape code in a
// path, key or file's text can neither break the line nor reach the terminal.
std::string escaped_line(const std::string& text);
std::string safe_name(const std::string& id);
bool is_safe_name(const std::string& name);

// Distinct safe names for a sequence of ids, deterministic for a given order, distinct also
// when compared case-insensitively (macOS, Windows and SMB shares fold case): a name already
// taken goes to its hashed form, then gets "-2", "-3", ... Names passed as `reserved` (e.g.
// "plots" in a run folder) are never given. Every name is at most kMaxSafeName bytes.
class SafeNames {
 public:
  explicit SafeNames(const std::vector<std::string>& reserved = {});
  std::string add(const std::string& id);

 private:
  bool take(const std::string& name);
  std::set<std::string> taken_;  // lower case
};

}  // namespace lodrefine
