// The planner's undo and redo: whole-document snapshots (TreeDocument.snapshot()), 200 kept. A
// structural edit is a step at once; typing in a field is one step once the field has been quiet for
// 0.6 s, and a structural edit first makes the typing before it its own step (settle()). No DOM.

export const HISTORY_LIMIT = 200;

export class History {
  /// `snapshot()`: the present as text; `onChange()`: after the steps changed (the page enables its
  /// Undo and Redo buttons). The page's test hook reads `past`, `future` and `current`.
  constructor(snapshot, { limit = HISTORY_LIMIT, quietMs = 600, onChange = () => {} } = {}) {
    this.snapshot = snapshot;
    this.limit = limit;
    this.quietMs = quietMs;
    this.onChange = onChange;
    this.past = [];
    this.future = [];
    this.current = '';
    this.timer = null;
  }
  get canUndo() { return this.past.length > 0; }
  get canRedo() { return this.future.length > 0; }
  /// The present is what it is now, with no step (the page opened, an undo step restored).
  present() {
    this.current = this.snapshot();
    this.onChange();
  }
  /// The present as a step when it differs from the last one; redo is then gone. True when a step was made.
  record() {
    clearTimeout(this.timer);
    this.timer = null;
    const now = this.snapshot();
    if (now === this.current) return false;
    this.past.push(this.current);
    if (this.past.length > this.limit) this.past.shift();
    this.current = now;
    this.future = [];
    this.onChange();
    return true;
  }
  /// A step once nothing else was typed for `quietMs`.
  recordLater() {
    clearTimeout(this.timer);
    this.timer = setTimeout(() => this.record(), this.quietMs);
  }
  /// Typing still waiting for its quiet time becomes its own step now.
  settle() { if (this.timer) this.record(); }
  /// The snapshot to restore, or null when there is no step to go back (forward) to.
  undo() { return this.travel('past', 'future'); }
  redo() { return this.travel('future', 'past'); }
  travel(from, to) {
    // Settled first: the step it makes replaces `future`, which must be the list the present goes to.
    this.settle();
    if (!this[from].length) return null;
    this[to].push(this.current);
    this.current = this[from].pop();
    return this.current;
  }
  /// Drops the pending step's timer (the page is left).
  close() {
    clearTimeout(this.timer);
    this.timer = null;
  }
}
