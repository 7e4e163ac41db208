// What a programming session cost its programmer, counted on the page as it happens: the clicks (on
// buttons, list entries, the 3D view), the choices made from lists (a select's change), and the fields
// typed into — one per stretch of typing in one field, however many characters — with the characters.
// Shown under the Planner's toolbar and read by the tests, which print it: the figure the Planner is
// judged by is how little a person has to do, and how little of it is typing.

/// Whether the field named `name` (its id or data-field) holds a coordinate: a position, a point, a pose
/// or one component of one (an x, y or z, a stand-off along y). A distance along a face or out of it (an
/// offset, a stand-off in mm) is one number with a unit, not a coordinate.
export function isCoordinateField(name) {
  return /position|pose|point|rpy|(^|[-_])[xyz](_m|_mm|_deg)?$|_[xyz]_(m|mm)$/.test(name || '');
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
  /// Counts what happens inside `root` until close(); `onChange(effort)` after every count.
  constructor(root, onChange = () => {}) {
    this.clicks = 0;
    this.choices = 0;
    this.fieldsTyped = 0;
    this.characters = 0;
    this.typing = null;  // the field of the current stretch of typing
    this.typedFields = [];  // the name of each field typed into, one per stretch of typing
    this.root = root;
    this.onChange = onChange;
    // Capture: a handler that re-renders the form must not hide the event from the count.
    this.listeners = {
      click: (e) => {
        // A click the page makes itself (a label forwarding to its control, a script) is not the person's.
        if (!e.isTrusted) return;
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
    for (const [type, fn] of Object.entries(this.listeners)) root.addEventListener(type, fn, true);
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
    for (const [type, fn] of Object.entries(this.listeners)) this.root.removeEventListener(type, fn, true);
  }
}
