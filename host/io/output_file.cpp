#include "io/output_file.hpp"

#include <sys/stat.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <csignal>
#include <cstring>
#include <filesystem>
#include <map>
#include <mutex>
#include <stdexcept>
#include <vector>

#include "clfractal/error.hpp"

namespace clfractal {

namespace fs = std::filesystem;

namespace {

// Temporaries that exist now, in fixed slots a signal handler can read without locks or
// allocation: a slot's name is complete before `used` is set, and cleared only after.
constexpr int slot_count = 64;
constexpr std::size_t slot_length = 4096;
char slot_names[slot_count][slot_length];
std::atomic<bool> slot_used[slot_count];

struct Deferred {
    std::string tmp, file, path;
};

std::mutex registry_mutex;
std::map<std::string, int> temporaries;  // name -> slot (-1: too many or too long to track)
std::vector<Deferred> deferred;          // renames waiting for OutputRun::commit
bool run_open = false;
struct sigaction previous_actions[3];
constexpr int cleanup_signals[3] = {SIGINT, SIGTERM, SIGHUP};

void remove_temporaries_on_signal(int sig) {
    for (int i = 0; i < slot_count; ++i)
        if (slot_used[i].load()) ::unlink(slot_names[i]);
    ::signal(sig, SIG_DFL);
    ::raise(sig);
}

void track(const std::string& tmp) {
    std::lock_guard<std::mutex> lock(registry_mutex);
    int slot = -1;
    if (tmp.size() < slot_length)
        for (int i = 0; i < slot_count && slot < 0; ++i)
            if (!slot_used[i].load()) slot = i;
    if (slot >= 0) {
        std::memcpy(slot_names[slot], tmp.c_str(), tmp.size() + 1);
        slot_used[slot].store(true);
    }
    temporaries[tmp] = slot;
}

/// Forgets `tmp`; true if it was a temporary (not a direct target).
bool untrack_locked(const std::string& tmp) {
    auto it = temporaries.find(tmp);
    if (it == temporaries.end()) return false;
    if (it->second >= 0) slot_used[it->second].store(false);
    temporaries.erase(it);
    return true;
}

bool untrack(const std::string& tmp) {
    std::lock_guard<std::mutex> lock(registry_mutex);
    return untrack_locked(tmp);
}

std::string folder_of(const fs::path& file) {
    const fs::path parent = file.parent_path();
    return parent.empty() ? std::string(".") : parent.string();
}

void check_folder(const std::string& path, const fs::path& file) {
    const std::string folder = folder_of(file);
    struct stat st {};
    if (::stat(folder.c_str(), &st) != 0)
        throw InputError(path + ": cannot write: folder '" + folder + "' " +
                         (errno == ENOENT ? std::string("does not exist") : std::strerror(errno)));
    if (!S_ISDIR(st.st_mode)) throw InputError(path + ": cannot write: '" + folder + "' is not a folder");
    if (::access(folder.c_str(), W_OK) != 0)
        throw InputError(path + ": cannot write in folder '" + folder + "': " + std::strerror(errno));
}

}  // namespace

OutputTarget check_output(const std::string& path) {
    if (path.empty()) throw InputError("an output path is empty");
    if (path == "-") return {path, "/dev/stdout", true};
    struct stat st {};
    if (::stat(path.c_str(), &st) == 0) {
        if (S_ISDIR(st.st_mode)) throw InputError(path + ": cannot write: is a folder");
        if (S_ISFIFO(st.st_mode) || S_ISCHR(st.st_mode)) {
            if (::access(path.c_str(), W_OK) != 0)
                throw InputError(path + ": cannot write: " + std::strerror(errno));
            return {path, path, true};
        }
        if (!S_ISREG(st.st_mode))
            throw InputError(path + ": cannot write: not a regular file, FIFO or character device");
        std::error_code ec;
        const fs::path file = fs::canonical(path, ec);  // through any symlinks
        if (ec) throw InputError(path + ": cannot write: " + ec.message());
        if (::access(file.c_str(), W_OK) != 0)
            throw InputError(path + ": cannot write: " + std::strerror(errno));
        check_folder(path, file);
        return {path, file.string(), false};
    }
    if (errno != ENOENT) throw InputError(path + ": cannot write: " + std::strerror(errno));
    // A new file, possibly behind a dangling symlink: it is created where the link points.
    fs::path file = path;
    for (int hops = 0;; ++hops) {
        std::error_code ec;
        if (!fs::is_symlink(fs::symlink_status(file, ec))) break;
        if (hops == 40) throw InputError(path + ": cannot write: too many levels of symbolic links");
        const fs::path target = fs::read_symlink(file, ec);
        if (ec) throw InputError(path + ": cannot write: " + ec.message());
        file = target.is_absolute() ? target : file.parent_path() / target;
    }
    check_folder(path, file);
    return {path, file.string(), false};
}

std::string temporary_path(const std::string& path, const std::string& suffix) {
    static std::atomic<unsigned> counter{0};
    const OutputTarget t = check_output(path);
    if (t.direct) return t.file;
    std::string tmp = t.file + ".tmp-" + std::to_string(::getpid()) + "-" + std::to_string(counter++) + suffix;
    track(tmp);
    return tmp;
}

void remove_temporary(const std::string& tmp) {
    if (!untrack(tmp)) return;
    std::error_code ignored;
    fs::remove(tmp, ignored);
}

void discard_temporary(const std::string& tmp, const std::string& path, const std::string& message) {
    remove_temporary(tmp);
    throw InputError(path + ": " + message);
}

void rename_into_place(const std::string& tmp, const std::string& path) {
    std::unique_lock<std::mutex> lock(registry_mutex);
    if (!temporaries.count(tmp)) return;  // a direct target: already written in place
    std::string file;
    try {
        lock.unlock();
        file = check_output(path).file;
        lock.lock();
    } catch (const InputError& e) {
        discard_temporary(tmp, path, std::string(e.what()).substr(path.size() + 2));
    }
    if (run_open) {
        deferred.push_back({tmp, file, path});
        return;
    }
    std::error_code ec;
    fs::rename(tmp, file, ec);
    lock.unlock();
    if (ec) discard_temporary(tmp, path, "cannot write: " + ec.message());
    untrack(tmp);
}

OutputRun::OutputRun() {
    std::lock_guard<std::mutex> lock(registry_mutex);
    if (run_open) throw std::logic_error("OutputRun: one is open already");
    run_open = true;
    struct sigaction action {};
    action.sa_handler = remove_temporaries_on_signal;
    sigemptyset(&action.sa_mask);
    for (int i = 0; i < 3; ++i) ::sigaction(cleanup_signals[i], &action, &previous_actions[i]);
}

OutputRun::~OutputRun() {
    std::lock_guard<std::mutex> lock(registry_mutex);
    for (auto& [tmp, slot] : temporaries) {
        std::error_code ignored;
        fs::remove(tmp, ignored);
        if (slot >= 0) slot_used[slot].store(false);
    }
    temporaries.clear();
    deferred.clear();
    run_open = false;
    for (int i = 0; i < 3; ++i) ::sigaction(cleanup_signals[i], &previous_actions[i], nullptr);
}

void OutputRun::commit() {
    std::unique_lock<std::mutex> lock(registry_mutex);
    std::vector<Deferred> todo;
    todo.swap(deferred);
    for (std::size_t i = 0; i < todo.size(); ++i) {
        std::error_code ec;
        fs::rename(todo[i].tmp, todo[i].file, ec);
        if (ec) {
            for (std::size_t k = i; k < todo.size(); ++k) {
                std::error_code ignored;
                fs::remove(todo[k].tmp, ignored);
                untrack_locked(todo[k].tmp);
            }
            throw InputError(todo[i].path + ": cannot write: " + ec.message());
        }
        untrack_locked(todo[i].tmp);
    }
}

}  // namespace clfractal
