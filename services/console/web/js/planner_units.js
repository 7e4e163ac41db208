// A number parameter with a unit, in the planner's form: the number and a choice of the units a recipe
// may write it in (docs/recipes.md, "Parameters": {"value": 5, "unit": "mm"} for a parameter in m). In
// the declared SI unit the value is a plain number, in another it is the quantity object, as the shipped
// recipes write them (recipes/crane_insert.json's tolerance in mm, duration in min). The controller's
// validator converts and checks the ranges; the factors here only scale the field's min and max hints.
import { el } from './api.js';

/// Units a parameter declared in the key may be written in, with the factor to the SI unit
/// (common/skill_model's units.cpp; the validator refuses anything else).
const OTHER_UNITS = {
  m: [['mm', 1e-3], ['cm', 1e-2], ['km', 1e3]],
  s: [['ms', 1e-3], ['min', 60], ['h', 3600]],
  N: [['kN', 1e3]],
  'N/s': [['kN/s', 1e3]],
  'm/s': [['mm/s', 1e-3]],
  rad: [['deg', Math.PI / 180]],
  'rad/s': [['deg/s', Math.PI / 180]],
  kg: [['g', 1e-3], ['t', 1e3]],
  Nm: [['Nmm', 1e-3]],
};

/// The number input of parameter description `p` with value `cur` (a number, a {value, unit} object or
/// undefined); `set(v)` stores the parameter (undefined: the default). With a unit, `input.unitSelect`
/// is the unit's choice, to be put after the input.
export function quantityInput(p, cur, set) {
  const quantity = cur && typeof cur === 'object' && typeof cur.value === 'number' ? cur : null;
  const units = [[p.unit, 1], ...(OTHER_UNITS[p.unit] || [])];
  // An opened recipe's unit this list lacks stays as written (the validator says whether it converts).
  if (quantity && !units.some(([u]) => u === quantity.unit)) units.push([String(quantity.unit), 1]);
  const input = el('input', { type: 'number', step: p.type === 'integer' ? '1' : 'any',
    value: quantity ? quantity.value : typeof cur === 'number' ? cur : '',
    placeholder: p.default !== undefined ? String(p.default) : '' });
  const hints = (factor) => {
    for (const k of ['min', 'max']) {
      if (p[k] === undefined) input.removeAttribute(k);
      else input.setAttribute(k, String(Number((p[k] / factor).toPrecision(12))));
    }
  };
  const store = () => {
    if (input.value === '') return set(undefined);
    const unit = select ? select.value : p.unit;
    set(unit === p.unit ? Number(input.value) : { value: Number(input.value), unit });
  };
  const select = p.unit && units.length > 1 ? el('select', { 'aria-label': `unit of ${p.name}`, id: `unit-${p.name}`, 'data-unit': p.name,
    onchange: () => { hints(units.find(([u]) => u === select.value)[1]); store(); } },
  ...units.map(([u]) => el('option', { value: u, selected: (quantity ? quantity.unit : p.unit) === u }, u))) : null;
  input.addEventListener('input', store);
  hints(quantity ? units.find(([u]) => u === quantity.unit)[1] : 1);
  input.unitSelect = select;
  return input;
}
