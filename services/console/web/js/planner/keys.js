// The planner's keys on the tree, when the focus is not in a text field: ↑/↓ select the previous/next
// node, Alt+↑/↓ move it, Delete, Ctrl+Z, Ctrl+Shift+Z or Ctrl+Y, Ctrl+C, Ctrl+X, Ctrl+V (⌘ on a Mac).

/// The command a key press `e` asks for: 'undo', 'redo', 'copy', 'cut', 'paste', 'delete', 'moveUp',
/// 'moveDown', 'previous', 'next', or '' for none. `selected`: whether a node is selected (Delete);
/// `textSelected()`: whether the page's text is selected (then Ctrl+C and Ctrl+X copy that text).
export function keyCommand(e, { selected, textSelected }) {
  const mod = e.ctrlKey || e.metaKey;
  const k = e.key.toLowerCase();
  if (mod && (k === 'c' || k === 'x') && textSelected()) return '';
  if (mod && k === 'z' && !e.shiftKey) return 'undo';
  if (mod && (k === 'y' || (k === 'z' && e.shiftKey))) return 'redo';
  if (mod && k === 'c') return 'copy';
  if (mod && k === 'x') return 'cut';
  if (mod && k === 'v') return 'paste';
  if (!mod && e.key === 'Delete' && selected) return 'delete';
  if (e.altKey && e.key === 'ArrowUp') return 'moveUp';
  if (e.altKey && e.key === 'ArrowDown') return 'moveDown';
  if (!mod && !e.altKey && e.key === 'ArrowUp') return 'previous';
  if (!mod && !e.altKey && e.key === 'ArrowDown') return 'next';
  return '';
}

/// Runs `commands[name]` for the keys pressed on the document while `active()` (no dialog open, the
/// plan shown), then `commands.focus()` (the selected node's button). `selected()`: whether a node is
/// selected. Returns the function that stops listening.
export function listenKeys(commands, { active, selected }) {
  const onKey = (e) => {
    const t = e.target;
    if (t instanceof HTMLInputElement || t instanceof HTMLTextAreaElement || t instanceof HTMLSelectElement || t?.isContentEditable) return;
    if (!active()) return;
    const name = keyCommand(e, { selected: Boolean(selected()), textSelected: () => Boolean(window.getSelection()?.toString()) });
    if (!name) return;
    commands[name]();
    e.preventDefault();
    commands.focus();
  };
  document.addEventListener('keydown', onKey);
  return () => document.removeEventListener('keydown', onKey);
}
