//! Undo and redo over the page's motion states: every edit pushes a new state; undo steps
//! back, redo forward, and a new edit after an undo drops the states that were undone.

/// A bounded linear history of states.
#[derive(Clone, Debug)]
pub struct History<T> {
    states: Vec<T>,
    /// Index of the current state in `states`.
    current: usize,
    limit: usize,
}

impl<T: Clone> History<T> {
    /// A history whose first state is `initial`, keeping at most `limit` states (the oldest
    /// are forgotten first).
    pub fn new(initial: T, limit: usize) -> History<T> {
        History {
            states: vec![initial],
            current: 0,
            limit: limit.max(1),
        }
    }

    pub fn current(&self) -> &T {
        &self.states[self.current]
    }

    /// Makes `state` current; the undone states after the current one are dropped.
    pub fn push(&mut self, state: T) {
        self.states.truncate(self.current + 1);
        self.states.push(state);
        if self.states.len() > self.limit {
            self.states.remove(0);
        }
        self.current = self.states.len() - 1;
    }

    pub fn can_undo(&self) -> bool {
        self.current > 0
    }

    pub fn can_redo(&self) -> bool {
        self.current + 1 < self.states.len()
    }

    /// Steps back; returns the new current state, or `None` at the start.
    pub fn undo(&mut self) -> Option<&T> {
        self.can_undo().then(|| {
            self.current -= 1;
            &self.states[self.current]
        })
    }

    /// Steps forward again after an undo.
    pub fn redo(&mut self) -> Option<&T> {
        self.can_redo().then(|| {
            self.current += 1;
            &self.states[self.current]
        })
    }

    /// The states from the oldest kept to the current one.
    pub fn path(&self) -> &[T] {
        &self.states[..=self.current]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn undo_redo_and_branching() {
        let mut h = History::new(0, 10);
        assert!(!h.can_undo() && !h.can_redo());
        h.push(1);
        h.push(2);
        assert_eq!(h.undo(), Some(&1));
        assert_eq!(h.undo(), Some(&0));
        assert_eq!(h.undo(), None);
        assert_eq!(h.redo(), Some(&1));
        // A new edit after an undo forgets the undone state 2.
        h.push(3);
        assert_eq!(h.redo(), None);
        assert_eq!(h.path(), &[0, 1, 3]);
    }

    #[test]
    fn the_oldest_states_go_first() {
        let mut h = History::new(0, 3);
        for i in 1..=5 {
            h.push(i);
        }
        assert_eq!(h.path(), &[3, 4, 5]);
        assert_eq!(h.undo(), Some(&4));
        assert_eq!(h.undo(), Some(&3));
        assert_eq!(h.undo(), None);
    }
}
