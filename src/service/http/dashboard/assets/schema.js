// Reading a process's input schema (the `inputs` of `/processes/{id}`) for the submit
// form: the schema of the member at a JSON pointer (following the alternative the current
// value takes), its unit, and its choices.
//
// A number's unit is the first parenthesized group of its description whose first word is
// an SI unit expression (`(m)`, `(N·s/m)`, `(m/s², ≥ 0)`) or `dimensionless`
// (tests/api/units.rs checks every number input of every process states one).

const UNITS = ['m', 's', 'Pa', 'N', 'kg', 'Hz', 'J', 'W', 'rad', 'degrees'];
const POWERS = ['', '²', '³', '⁴', '⁻¹', '⁻²'];

function isUnit(word) {
  return word !== '' && word.split(/[/·]/).every((factor, k) => (k === 0 && factor === '1')
    || UNITS.some((unit) => POWERS.some((power) => factor === `${unit}${power}`)));
}

/** The unit a description states, `dimensionless`, or null. */
export function unitOf(description) {
  for (const match of String(description || '').matchAll(/\(([^()]*)\)/g)) {
    const word = match[1].trim().split(/[,; ]/)[0];
    if (word === 'dimensionless' || isUnit(word)) return word;
  }
  return null;
}

/** The alternatives of a schema: its oneOf/anyOf members (nested ones flattened), an
 *  allOf merged into one, or the schema itself. */
export function alternatives(schema) {
  if (!schema || typeof schema !== 'object') return [];
  if (Array.isArray(schema.allOf)) {
    const merged = {properties: {}, required: []};
    for (const part of schema.allOf.flatMap(alternatives)) {
      Object.assign(merged.properties, part.properties || {});
      merged.required.push(...(part.required || []));
    }
    return [merged];
  }
  const members = schema.oneOf || schema.anyOf;
  return Array.isArray(members) ? members.flatMap(alternatives) : [schema];
}

const types = (schema) => (Array.isArray(schema.type) ? schema.type : [schema.type]);

/** The `type` tag of an object alternative (its `type` member's single value), or null. */
function tagOf(variant) {
  const tag = variant.properties && variant.properties.type;
  return tag && Array.isArray(tag.enum) && tag.enum.length === 1 ? tag.enum[0] : null;
}

/** The object alternatives of a schema that carry a `type` tag: [{tag, variant}]. */
export function taggedVariants(schema) {
  return alternatives(schema).filter((s) => s.properties && tagOf(s) !== null)
    .map((variant) => ({tag: tagOf(variant), variant}));
}

/** The object alternative that fits `value`: by its `type` tag, else by its members. */
function variantFor(schema, value) {
  const objects = alternatives(schema).filter((s) => s.properties);
  if (!objects.length) return null;
  if (value && typeof value === 'object' && !Array.isArray(value)) {
    const tagged = objects.find((s) => value.type !== undefined && tagOf(s) === value.type);
    if (tagged) return tagged;
    const keys = Object.keys(value);
    return objects.find((s) => keys.every((key) => key in s.properties)) || objects[0];
  }
  return objects[0];
}

function itemsOf(schema) {
  const array = alternatives(schema).find((s) => types(s).includes('array'));
  return array ? array.items : null;
}

/** The schema of the member at `pointer` of `body` (`root` describing `body`), or null. */
export function schemaAt(root, body, pointer) {
  const tokens = pointer.split('/').slice(1).map((t) => t.replaceAll('~1', '/').replaceAll('~0', '~'));
  let schema = root;
  let value = body;
  for (const token of tokens) {
    if (!schema) return null;
    if (Array.isArray(value)) {
      schema = itemsOf(schema);
      value = value[Number(token)];
      continue;
    }
    const variant = variantFor(schema, value);
    if (!variant) return null;
    schema = variant.properties[token] || null;
    value = value && typeof value === 'object' ? value[token] : undefined;
  }
  return schema;
}

/** A property's description, or its first alternative's. */
function descriptionOf(schema) {
  if (schema.description) return schema.description;
  const found = [...(schema.oneOf || []), ...(schema.anyOf || [])].find((s) => s.description);
  return found ? found.description : '';
}

/**
 * What a form field needs of its schema: `unit` (a unit, `dimensionless`, or `integer`
 * for a whole number: a count, an index, a seed), `choices` (the values of a string enumeration, null otherwise), `keywords`
 * (string values allowed besides a number, e.g. `auto`) and the `description`.
 */
export function fieldInfo(schema) {
  if (!schema) return {unit: null, choices: null, keywords: [], description: ''};
  const description = descriptionOf(schema);
  const all = alternatives(schema);
  const kinds = all.flatMap((s) => types(s).concat(types(s).includes('array') && s.items ? types(s.items) : []));
  const strings = all.filter((s) => Array.isArray(s.enum)).flatMap((s) => s.enum)
    .filter((v) => typeof v === 'string');
  const numeric = kinds.includes('number') || kinds.includes('integer');
  let unit = null;
  if (kinds.includes('number')) unit = unitOf(description);
  else if (kinds.includes('integer')) unit = 'integer';
  return {
    unit,
    choices: !numeric && strings.length ? strings : null,
    keywords: numeric ? strings : [],
    description,
  };
}
