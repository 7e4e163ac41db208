// What a programming session cost its programmer, counted on the page as it happens: the clicks (on
// buttons, list entries, the 3D view), the choices made from lists (a select's change), and the fields
// typed into — one per stretch of typing in one field, however many characters — with the characters. A
// drag (the 3D view orbited) is no click; the confirmation dialog's Yes and No are.
// Shown under the Planner's toolbar and read by the tests, which print it: the figure the Planner is
// judged by is how little a person has to do, and how little of it is typing.

/// Whether the field named `name` (its id or data-field) holds a coordinate: a position, a point, a pose
/// or one component of one (an x, y or z, a stand-off along y). A distance along a face or out of it (an
/// offset, a stand-off in mm) is one number with a unit, not a coordinate.
export function isCoordinateField(name) {
  return /position|pose|point|rpy|(^|[-_])[xyz](_m|_mm|_deg)?$|_[xyz]_(m|mm)$/.test(name || '');
}

/// Whether a click at `e` ends a drag from `down` ([x, y] of the press): moved more than 4 px, as the 3D
/// view tells a pick from an orbit.
export function isDrag(down, e) {
  return Boolean(down) && Math.hypot(e.clientX - down[0], e.clientY - down[1]) > 4;
}

/// The name a typed field is reported by: its id, its data-field, or its label.
function fieldName(t) {
  return t.id || t.dataset.field || t.getAttribute('aria-label') || t.name || '(unnamed)';
}

/// Whether typing into `t` is typing a value (a text, number or search field, or a text area).
function typedInto(t) {
  if (t instanceof HTMLTextAreaElement) return true;
  return t instanceof HTMLInputElement && ['text', 'number', 'search', ''].includes(t.type);
}

export class Effort {
  /// Counts what happens inside `root` (an element, or a list of them: the page and its confirmation
  /// dialog) until close(); `onChange(effort)` after every count.
  constructor(root, onChange = () => {}) {
    this.clicks = 0;
    this.choices = 0;
    this.fieldsTyped = 0;
    this.characters = 0;
    this.typing = null;  // the field of the current stretch of typing
    this.typedFields = [];  // the name of each field typed into, one per stretch of typing
    this.roots = Array.isArray(root) ? root : [root];
    this.down = null;  // where the last press was: a press released elsewhere is a drag (the 3D view's orbit), not a click
    this.onChange = onChange;
    // Capture: a handler that re-renders the form must not hide the event from the count.
    this.listeners = {
      pointerdown: (e) => { this.down = [e.clientX, e.clientY]; },
      click: (e) => {
        // A click the page makes itself (a label forwarding to its control, a script) is not the person's.
        if (!e.isTrusted) return;
        if (isDrag(this.down, e)) return;
        this.clicks += 1;
        this.typing = null;
        this.onChange(this);
      },
      change: (e) => {
        if (!(e.target instanceof HTMLSelectElement)) return;
        this.choices += 1;
        this.typing = null;
        this.onChange(this);
      },
      input: (e) => {
        if (!typedInto(e.target)) return;
        if (this.typing !== e.target) {
          this.fieldsTyped += 1;
          this.typedFields.push(fieldName(e.target));
        }
        this.typing = e.target;
        this.characters += typeof e.data === 'string' ? e.data.length : 0;
        this.onChange(this);
      },
      focusin: (e) => { if (e.target !== this.typing) this.typing = null; },
    };
    for (const r of this.roots) for (const [type, fn] of Object.entries(this.listeners)) r.addEventListener(type, fn, true);
  }

  /// {clicks, choices, fields_typed, characters}: what the tests print.
  counts() {
    return { clicks: this.clicks, choices: this.choices, fields_typed: this.fieldsTyped, characters: this.characters };
  }

  /// The fields typed into, in order ({name, coordinate}): a coordinate typed is what the Planner exists
  /// to spare its programmer.
  typed() {
    return this.typedFields.map((name) => ({ name, coordinate: isCoordinateField(name) }));
  }

  /// One line for the page.
  text() {
    const n = (k, one, many) => `${k} ${k === 1 ? one : many}`;
    return `This session: ${n(this.clicks, 'click', 'clicks')}, ${n(this.choices, 'choice from a list', 'choices from lists')}, `
      + `${n(this.fieldsTyped, 'field typed', 'fields typed')} (${n(this.characters, 'character', 'characters')})`;
  }

  close() {
    for (const r of this.roots) for (const [type, fn] of Object.entries(this.listeners)) r.removeEventListener(type, fn, true);
  }
}
