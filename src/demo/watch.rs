//! Shader hot reload's eyes: polls the modification times of every file under the GLSL root.
//!
//! Polling a few times a second needs no dependency and no OS notification API, and the GLSL
//! tree is a few dozen files: one scan costs well under a millisecond.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant, SystemTime};

/// How often the tree is scanned.
const POLL_INTERVAL: Duration = Duration::from_millis(300);
/// Deepest directory nesting scanned (a symlink loop must not recurse forever).
const MAX_DEPTH: usize = 8;

/// Watches a directory tree for changed, added or removed files.
pub struct ShaderWatcher {
    root: PathBuf,
    seen: BTreeMap<PathBuf, Option<SystemTime>>,
    last_poll: Instant,
}

impl ShaderWatcher {
    /// Starts watching `root` (its current state is the baseline).
    pub fn new(root: &Path) -> Self {
        Self {
            root: root.to_path_buf(),
            seen: scan(root),
            last_poll: Instant::now(),
        }
    }

    /// The files that changed since the last call, when the poll interval has passed (empty
    /// otherwise, and when nothing changed).
    pub fn poll(&mut self) -> Vec<PathBuf> {
        if self.last_poll.elapsed() < POLL_INTERVAL {
            return Vec::new();
        }
        self.poll_now()
    }

    /// Scans now, whatever the interval.
    pub fn poll_now(&mut self) -> Vec<PathBuf> {
        self.last_poll = Instant::now();
        let now = scan(&self.root);
        let mut changed: Vec<PathBuf> = now
            .iter()
            .filter(|(path, time)| self.seen.get(*path) != Some(time))
            .map(|(path, _)| path.clone())
            .collect();
        changed.extend(self.seen.keys().filter(|p| !now.contains_key(*p)).cloned());
        self.seen = now;
        changed
    }
}

fn scan(root: &Path) -> BTreeMap<PathBuf, Option<SystemTime>> {
    let mut files = BTreeMap::new();
    let mut stack = vec![(root.to_path_buf(), 0)];
    while let Some((dir, depth)) = stack.pop() {
        let Ok(entries) = std::fs::read_dir(&dir) else {
            continue;
        };
        for entry in entries.flatten() {
            let path = entry.path();
            let Ok(metadata) = entry.metadata() else {
                continue;
            };
            if metadata.is_dir() {
                if depth < MAX_DEPTH {
                    stack.push((path, depth + 1));
                }
            } else {
                files.insert(path, metadata.modified().ok());
            }
        }
    }
    files
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sees_edits_additions_and_removals() {
        let dir = std::env::temp_dir().join(format!("lucent-watch-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(dir.join("sub")).unwrap();
        let file = dir.join("sub/a.frag");
        std::fs::write(&file, "1").unwrap();
        let mut watcher = ShaderWatcher::new(&dir);
        assert!(watcher.poll_now().is_empty());
        // Make sure the new modification time differs even on coarse-grained file systems.
        let later = SystemTime::now() + Duration::from_secs(5);
        std::fs::write(&file, "2").unwrap();
        std::fs::File::options()
            .write(true)
            .open(&file)
            .unwrap()
            .set_modified(later)
            .unwrap();
        assert_eq!(watcher.poll_now(), vec![file.clone()]);
        let added = dir.join("b.glsl");
        std::fs::write(&added, "x").unwrap();
        assert_eq!(watcher.poll_now(), vec![added.clone()]);
        std::fs::remove_file(&added).unwrap();
        assert_eq!(watcher.poll_now(), vec![added]);
        assert!(watcher.poll().is_empty(), "interval not passed yet");
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
