//! A result computed on the async compute pool for a key: the sensors'
//! day and year and the annual study use it (a leaf of the viewer's graph).

use bevy::tasks::{AsyncComputeTaskPool, Task, block_on, futures_lite::future};

/// A result computed in the background for a key (what it was asked for).
pub struct Background<K, T> {
    pub(super) key: Option<K>,
    pub(super) task: Option<Task<T>>,
    /// The result, once done; `None` while computing or when not asked.
    pub values: Option<T>,
}

impl<K, T> Default for Background<K, T> {
    fn default() -> Self {
        Self { key: None, task: None, values: None }
    }
}

impl<K: PartialEq, T: Send + 'static> Background<K, T> {
    /// Whether a task is running.
    pub fn is_running(&self) -> bool {
        self.task.is_some()
    }

    /// Takes the result if the task has finished.
    pub(super) fn collect(&mut self) {
        if let Some(task) = &mut self.task
            && let Some(values) = block_on(future::poll_once(task))
        {
            self.values = Some(values);
            self.task = None;
        }
    }

    /// Starts `work` for `key` on the async compute pool, in place of
    /// whatever was there.
    pub(super) fn start(&mut self, key: Option<K>, work: impl FnOnce() -> T + Send + 'static) {
        self.key = key;
        self.values = None;
        self.task = Some(AsyncComputeTaskPool::get().spawn(async move { work() }));
    }
}
