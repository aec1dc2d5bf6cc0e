// The HDF5 session, handles and error text, whole files (atomic writes,
// reads, the global-heap check) and groups.
#include <fcntl.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <filesystem>
#include <utility>

#include "analysis/runfile/hdf5_util_impl.h"
#include "stack/base/files.h"

namespace adse::runfile::internal {
namespace {

std::mutex& Hdf5Mutex() {
  static std::mutex mutex;
  return mutex;
}

herr_t CollectErrors(unsigned /*n*/, const H5E_error2_t* err, void* data) {
  auto* out = static_cast<std::vector<std::string>*>(data);
  if (err != nullptr && err->desc != nullptr && err->desc[0] != '\0') {
    out->push_back(err->desc);
  }
  return 0;
}

}  // namespace

std::string PathOf(hid_t loc, const std::string& name) {
  char buffer[512];
  const ssize_t n = H5Iget_name(loc, buffer, sizeof(buffer));
  std::string parent = n > 0 ? std::string(buffer) : std::string("?");
  if (name.empty() || name == ".") return parent;
  if (parent.empty() || parent.back() != '/') parent += '/';
  return parent + name;
}

Status ReadError(const std::string& what) { return Status::Corruption(what); }
Status ReadHdf5Error(const std::string& object, const std::string& action) {
  return Status::Corruption(object + ": " + action + ": " + TakeHdf5Error());
}
Status WriteHdf5Error(const std::string& object, const std::string& action) {
  return Status::IoError(object + ": " + action + ": " + TakeHdf5Error());
}
Hdf5Session::Hdf5Session() : lock_(Hdf5Mutex()) {
  // Every open allocates a metadata cache of over 0.5 MB from HDF5's "regular"
  // free list, whose default 64 KB limit returns it to the system at each
  // close: reading many files then maps and zeroes it afresh each time.
  // Kept instead, bounded (bytes: all regular lists, one list; the array
  // and block lists keep their defaults).
  static const bool kept =
      H5set_free_list_limits(16 << 20, 4 << 20, 4 << 20, 256 << 10, 16 << 20,
                             1 << 20) >= 0;
  (void)kept;
  if (H5Eget_auto2(H5E_DEFAULT, &saved_func_, &saved_data_) >= 0) {
    restore_ = true;
  }
  H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);
}

Hdf5Session::~Hdf5Session() {
  H5Eclear2(H5E_DEFAULT);
  if (restore_) H5Eset_auto2(H5E_DEFAULT, saved_func_, saved_data_);
}

bool Handle::Close() {
  if (id_ < 0) return true;
  const hid_t id = std::exchange(id_, -1);
  herr_t rc = -1;
  switch (H5Iget_type(id)) {
    case H5I_FILE:
      rc = H5Fclose(id);
      break;
    case H5I_GROUP:
      rc = H5Gclose(id);
      break;
    case H5I_DATASET:
      rc = H5Dclose(id);
      break;
    case H5I_DATASPACE:
      rc = H5Sclose(id);
      break;
    case H5I_DATATYPE:
      rc = H5Tclose(id);
      break;
    case H5I_ATTR:
      rc = H5Aclose(id);
      break;
    case H5I_GENPROP_LST:
      rc = H5Pclose(id);
      break;
    default:
      rc = H5Idec_ref(id) < 0 ? -1 : 0;
      break;
  }
  return rc >= 0;
}

std::string TakeHdf5Error() {
  std::vector<std::string> descriptions;
  H5Ewalk2(H5E_DEFAULT, H5E_WALK_DOWNWARD, CollectErrors, &descriptions);
  H5Eclear2(H5E_DEFAULT);
  if (descriptions.empty()) return "unknown HDF5 error";
  // Downward: from the API call to the deepest cause. Name both when they
  // differ, e.g. "unable to open file (truncated file: eof = ...)".
  if (descriptions.size() == 1) return descriptions.front();
  return descriptions.front() + " (" + descriptions.back() + ")";
}

Status WriteFileAtomically(
    const std::string& path,
    const std::function<Status(hid_t file)>& write_contents, Env* env) {
  namespace fs = std::filesystem;
  const fs::path target(path);
  if (target.has_parent_path()) {
    ADSE_RETURN_IF_ERROR(MakeDirs(target.parent_path().string(), env));
  }
  const std::string tmp = TemporaryPathFor(path);
  Status status;
  {
    Hdf5Session session;
    Handle fapl = MakeFileAccessProps();
    // No modification time on the root group either, so the same contents
    // give the same bytes (datasets and groups already track none).
    Handle fcpl(H5Pcreate(H5P_FILE_CREATE));
    if (fcpl.valid()) H5Pset_obj_track_times(fcpl.get(), false);
    Handle file(H5Fcreate(tmp.c_str(), H5F_ACC_TRUNC,
                          fcpl.valid() ? fcpl.get() : H5P_DEFAULT, fapl.get()));
    if (!file.valid()) {
      status = Status::IoError(tmp +
                               ": cannot create HDF5 file: " + TakeHdf5Error());
    } else {
      status = write_contents(file.get()).WithContext(tmp);
      // Closing flushes metadata; a failure here means the file is bad.
      if (!file.Close() && status.ok()) {
        status = Status::IoError(tmp + ": closing: " + TakeHdf5Error());
      }
    }
  }
  if (!status.ok()) {
    (void)env->RemoveFile(tmp);
    return status;
  }
  return CommitTemporary(tmp, path, env);
}

// The walk mirrors the collection layout of the HDF5 file
// format (version 1, 8-byte lengths, what adse and h5py write): "GCOL",
// version, 3 reserved bytes, collection size, then objects of a 16-byte
// header (index, references, reserved, size) and 8-byte aligned data.
Status CheckGlobalHeaps(const std::string& path) {
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) {
    return Status::IoError(path + ": cannot read: " + std::strerror(errno));
  }
  struct stat info;
  void* map = MAP_FAILED;
  size_t n = 0;
  if (::fstat(fd, &info) == 0 && info.st_size > 0) {
    n = static_cast<size_t>(info.st_size);
    map = ::mmap(nullptr, n, PROT_READ, MAP_PRIVATE, fd, 0);
  }
  const int error = errno;
  ::close(fd);  // the mapping stays valid
  if (n == 0) return Status::Ok();
  if (map == MAP_FAILED) {
    return Status::IoError(path + ": cannot read: " + std::strerror(error));
  }
  const unsigned char* bytes = static_cast<const unsigned char*>(map);
  auto u64 = [&](size_t at) {
    uint64_t v = 0;
    for (int i = 7; i >= 0; --i) v = (v << 8) | bytes[at + i];
    return v;
  };
  constexpr size_t kHeader = 16, kMinCollection = 4096;
  Status status;
  for (size_t at = 0; status.ok() && at + kHeader <= n; ++at) {
    const void* found = ::memmem(bytes + at, n - at, "GCOL", 4);
    if (found == nullptr) break;
    at = static_cast<size_t>(static_cast<const unsigned char*>(found) - bytes);
    if (at + kHeader > n) break;
    const uint64_t size = u64(at + 8);
    if (bytes[at + 4] != 1 || size < kMinCollection || size > n - at) {
      continue;  // not a collection header (e.g. the text "GCOL" in data)
    }
    const size_t end = at + static_cast<size_t>(size);
    for (size_t p = at + kHeader; p + kHeader <= end;) {
      const unsigned index = bytes[p] | (bytes[p + 1] << 8);
      const uint64_t object = u64(p + 8);
      const uint64_t room = end - p;  // bytes left in the collection
      if (index == 0) {               // free space; HDF5 parses on after it
        if (object == 0) {
          status = Status::Corruption(
              path + ": damaged HDF5 global heap at byte " +
              std::to_string(at) +
              " (an empty free-space object, which HDF5 cannot read past)");
          break;
        }
        if (object > room) break;  // trailing free space
        p += static_cast<size_t>(object);
        continue;
      }
      // Compared before any arithmetic: a size near 2^64 must not wrap.
      if (object > room - kHeader || kHeader + ((object + 7) / 8) * 8 > room) {
        status = Status::Corruption(
            path + ": damaged HDF5 global heap at byte " + std::to_string(at) +
            " (object " + std::to_string(index) + " claims " +
            std::to_string(object) + " bytes, more than its collection)");
        break;
      }
      p += static_cast<size_t>(kHeader + ((object + 7) / 8) * 8);
    }
  }
  ::munmap(map, n);
  return status;
}

Status ReadFileContents(
    const std::string& path, const std::string& expected,
    const std::function<Status(hid_t file)>& read_contents) {
  namespace fs = std::filesystem;
  std::error_code ec;
  if (!fs::exists(path, ec)) return Status::NotFound(path + ": no such file");
  if (fs::is_directory(path, ec)) {
    return Status::InvalidArgument(path + ": is a directory, expected " +
                                   expected);
  }
  Hdf5Session session;
  const htri_t is_hdf5 = IsHdf5File(path);
  if (is_hdf5 < 0) {
    return Status::IoError(path + ": cannot read: " + TakeHdf5Error());
  }
  if (is_hdf5 == 0) {
    return Status::Corruption(path + ": not an HDF5 file (no HDF5 signature)");
  }
  ADSE_RETURN_IF_ERROR(CheckGlobalHeaps(path));
  Handle fapl = MakeFileAccessProps();
  Handle file(H5Fopen(path.c_str(), H5F_ACC_RDONLY, fapl.get()));
  if (!file.valid()) {
    return Status::Corruption(path +
                              ": cannot open as HDF5 (truncated or "
                              "damaged?): " +
                              TakeHdf5Error());
  }
  Status status = read_contents(file.get());
  if (!status.ok()) return Status::Corruption(path + ": " + status.message());
  return Status::Ok();
}

Handle MakeFileAccessProps() {
  Handle fapl(H5Pcreate(H5P_FILE_ACCESS));
  if (!fapl.valid()) return fapl;
#if H5_VERSION_GE(1, 10, 7)
  H5Pset_file_locking(fapl.get(), /*use_file_locking=*/false,
                      /*ignore_when_disabled=*/true);
#endif
  // Closing the file id really closes the file, whatever ids leak.
  H5Pset_fclose_degree(fapl.get(), H5F_CLOSE_STRONG);
  // The 1.10 file format checksums all metadata, so damage is reported
  // instead of being read (or crashing libhdf5). Pinned, not "latest", so
  // files stay readable by HDF5 1.10+ whatever library adse is built with.
#if H5_VERSION_GE(1, 10, 2)
  H5Pset_libver_bounds(fapl.get(), H5F_LIBVER_V110, H5F_LIBVER_V110);
#endif
  return fapl;
}

htri_t IsHdf5File(const std::string& path) {
#if H5_VERSION_GE(1, 12, 0)
  Handle fapl = MakeFileAccessProps();
  return H5Fis_accessible(path.c_str(), fapl.get());
#else
  return H5Fis_hdf5(path.c_str());
#endif
}

Handle MakeGroupCreateProps() {
  Handle gcpl(H5Pcreate(H5P_GROUP_CREATE));
  if (gcpl.valid()) H5Pset_obj_track_times(gcpl.get(), false);
  return gcpl;
}

Result<Handle> CreateGroup(hid_t parent, const std::string& name) {
  Handle gcpl = MakeGroupCreateProps();
  Handle group(
      H5Gcreate2(parent, name.c_str(), H5P_DEFAULT, gcpl.get(), H5P_DEFAULT));
  if (!group.valid()) {
    return Status::IoError("creating group " + PathOf(parent, name) + ": " +
                           TakeHdf5Error());
  }
  return group;
}

Result<Handle> OpenGroup(hid_t file, const std::string& path) {
  if (GetObjectKind(file, path) != ObjectKind::kGroup) {
    return Status::Corruption(path + ": missing group");
  }
  Handle group(H5Gopen2(file, path.c_str(), H5P_DEFAULT));
  if (!group.valid()) {
    return Status::Corruption(path + ": opening: " + TakeHdf5Error());
  }
  return group;
}

ObjectKind GetObjectKind(hid_t file, const std::string& path) {
  // H5Lexists fails (rather than returning 0) on a missing parent, so walk
  // the components.
  size_t pos = 0;
  while (pos != std::string::npos) {
    pos = path.find('/', pos + 1);
    const std::string prefix = path.substr(0, pos);
    if (prefix.empty() || prefix == "/") continue;
    if (H5Lexists(file, prefix.c_str(), H5P_DEFAULT) <= 0) {
      H5Eclear2(H5E_DEFAULT);
      return ObjectKind::kMissing;
    }
  }
  Handle object(H5Oopen(file, path.c_str(), H5P_DEFAULT));
  if (!object.valid()) {
    H5Eclear2(H5E_DEFAULT);
    return ObjectKind::kOther;  // e.g. a dangling soft link
  }
  switch (H5Iget_type(object.get())) {
    case H5I_GROUP:
      return ObjectKind::kGroup;
    case H5I_DATASET:
      return ObjectKind::kDataset;
    default:
      return ObjectKind::kOther;
  }
}

const char* TypeClassName(H5T_class_t type_class) {
  switch (type_class) {
    case H5T_INTEGER:
      return "int";
    case H5T_FLOAT:
      return "float";
    case H5T_STRING:
      return "string";
    case H5T_ENUM:
      return "enum";
    case H5T_COMPOUND:
      return "compound";
    case H5T_TIME:
      return "time";
    case H5T_BITFIELD:
      return "bitfield";
    case H5T_OPAQUE:
      return "opaque";
    case H5T_REFERENCE:
      return "reference";
    case H5T_VLEN:
      return "vlen";
    case H5T_ARRAY:
      return "array";
    default:
      return "unknown";
  }
}

}  // namespace adse::runfile::internal
