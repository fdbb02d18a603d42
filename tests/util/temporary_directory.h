// Unique temporary directories for tests.
//
// Every test that writes files writes them into its own TemporaryDirectory:
// a fresh directory <system temp>/<prefix>-XXXXXX (mkdtemp; the system temp
// directory is std::filesystem::temp_directory_path(), i.e. $TMPDIR or /tmp)
// that is removed with everything in it when the object is destroyed. Two
// runs of the suite on one machine, or two tests running in parallel, never
// share a file, and nothing stays behind in /tmp.
//
//   const testing::TemporaryDirectory dir("diffpd-obj-reader");
//   const std::string path = dir.WriteFile("tet.obj", "v 0 0 0\n...");
//   ReadObj(path);
//   ReadObj(dir.File("missing.obj"));  // a path in the directory, not created
#pragma once

#include <filesystem>
#include <string>

namespace diffpd::testing {

class TemporaryDirectory {
 public:
  // Creates the directory. `prefix` names it for a person looking at the
  // temp directory; it must be non-empty and hold no '/'. Throws
  // std::invalid_argument for a bad prefix and std::runtime_error when the
  // directory cannot be created.
  explicit TemporaryDirectory(const std::string& prefix = "diffpd-test");
  // Removes the directory and its contents; errors are ignored (a test must
  // not fail in its clean-up).
  ~TemporaryDirectory();
  TemporaryDirectory(const TemporaryDirectory&) = delete;
  TemporaryDirectory& operator=(const TemporaryDirectory&) = delete;

  // The directory (absolute).
  const std::filesystem::path& path() const { return path_; }
  // path() / name as a string; nothing is created.
  std::string File(const std::string& name) const;
  // Writes `text` to path() / name (replacing the file) and returns that
  // path. Throws std::runtime_error when the file cannot be written.
  std::string WriteFile(const std::string& name, const std::string& text) const;

 private:
  std::filesystem::path path_;
};

}  // namespace diffpd::testing
