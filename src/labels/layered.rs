//! Label values unique across layers. The colour table and the visibility bits are indexed by
//! value, but Slicer numbers each layer's segments 1, 2, … anew: a value an earlier layer holds
//! becomes an unused one in the later layer, its description with it, and a note says so.

use rayon::prelude::*;

use super::names::Described;

/// How many renumbered labels a note names before it counts the rest.
const NAMED: usize = 3;

/// Every value a u16 label may take.
const VALUES: usize = 1 << 16;

/// Renumbers, in each layer after the first, the values an earlier layer holds (voxels and
/// descriptions); the reason where the layers together hold more than 65535 values.
pub(super) fn unique_across_layers(
    layers: &mut [Vec<u16>],
    described: &mut [Described],
    notes: &mut Vec<String>,
) -> Result<(), String> {
    if layers.len() < 2 {
        return Ok(());
    }
    // Values the layers before hold, and (while a layer is renumbered) its own too.
    let mut taken = vec![false; VALUES];
    taken[0] = true;
    let mut renamed = Vec::new();
    for (k, layer) in layers.iter_mut().enumerate() {
        let mut present = vec![false; VALUES];
        for &v in layer.iter() {
            present[usize::from(v)] = true;
        }
        for d in described.iter().filter(|d| usize::from(d.layer) == k) {
            present[usize::from(d.value)] = true;
        }
        present[0] = false;
        let clashing: Vec<usize> = (1..VALUES).filter(|&v| present[v] && taken[v]).collect();
        for v in (1..VALUES).filter(|&v| present[v]) {
            taken[v] = true;
        }
        if clashing.is_empty() {
            continue;
        }
        let mut map: Vec<u16> = (0..=u16::MAX).collect();
        let mut free = 1;
        for v in clashing {
            while free < VALUES && taken[free] {
                free += 1;
            }
            let Ok(new) = u16::try_from(free) else {
                return Err("the layers together hold more than 65535 labels".into());
            };
            taken[free] = true;
            map[v] = new;
            renamed.push((k, v as u16, new));
        }
        layer.par_iter_mut().for_each(|l| *l = map[usize::from(*l)]);
        for d in described.iter_mut().filter(|d| usize::from(d.layer) == k) {
            d.value = map[usize::from(d.value)];
        }
    }
    note_renamed(&renamed, described, notes);
    Ok(())
}

/// The note on renumbered labels: the first few by name, then how many more.
fn note_renamed(renamed: &[(usize, u16, u16)], described: &[Described], notes: &mut Vec<String>) {
    if renamed.is_empty() {
        return;
    }
    let named: Vec<String> = renamed
        .iter()
        .take(NAMED)
        .map(|&(layer, old, new)| {
            let name = described
                .iter()
                .find(|d| usize::from(d.layer) == layer && d.value == new)
                .map_or_else(String::new, |d| format!(" ({})", d.name));
            format!("layer {layer}'s label {old}{name} is label {new}")
        })
        .collect();
    let more = renamed.len().saturating_sub(NAMED);
    let rest = if more > 0 {
        format!(" and {more} more")
    } else {
        String::new()
    };
    notes.push(format!(
        "label values differ between layers here: {}{rest}",
        named.join(", ")
    ));
}

#[cfg(test)]
mod tests {
    use super::*;

    fn described(layer: u16, value: u16, name: &str) -> Described {
        Described {
            value,
            layer,
            name: name.into(),
            colour: None,
        }
    }

    #[test]
    fn a_value_an_earlier_layer_holds_takes_a_free_one() {
        let mut layers = vec![vec![0, 1, 2, 2], vec![1, 1, 0, 3], vec![3, 0, 4, 1]];
        let mut d = vec![
            described(0, 1, "liver"),
            described(0, 2, "kidney"),
            described(1, 1, "tumour"),
            described(1, 3, "vessel"),
            described(2, 1, "cyst"),
            described(2, 3, "duct"),
            described(2, 4, "stone"),
        ];
        let mut notes = Vec::new();
        unique_across_layers(&mut layers, &mut d, &mut notes).expect("renumbered");
        // Layer 1's 1 clashes (4 is the first free value); its 3 is new. Layer 2's 1 and 3
        // clash (5, 6), its 4 clashes with layer 1's new 4 (7).
        assert_eq!(
            layers,
            vec![vec![0, 1, 2, 2], vec![4, 4, 0, 3], vec![6, 0, 7, 5]]
        );
        let values: Vec<(u16, u16, &str)> = d
            .iter()
            .map(|d| (d.layer, d.value, d.name.as_str()))
            .collect();
        assert_eq!(
            values,
            [
                (0, 1, "liver"),
                (0, 2, "kidney"),
                (1, 4, "tumour"),
                (1, 3, "vessel"),
                (2, 5, "cyst"),
                (2, 6, "duct"),
                (2, 7, "stone"),
            ]
        );
        assert_eq!(notes.len(), 1);
        assert!(
            notes[0].contains("layer 1's label 1 (tumour) is label 4")
                && notes[0].contains("1 more"),
            "{notes:?}"
        );
        // Every value one layer's only.
        for v in 1..=u16::MAX {
            let holding = layers.iter().filter(|l| l.contains(&v)).count();
            assert!(holding <= 1, "label {v} in {holding} layers");
        }
    }

    #[test]
    fn one_layer_is_left_as_it_is() {
        let mut layers = vec![vec![0, 7, 7]];
        let mut d = vec![described(0, 7, "a")];
        let mut notes = Vec::new();
        unique_across_layers(&mut layers, &mut d, &mut notes).expect("nothing to do");
        assert_eq!(layers, vec![vec![0, 7, 7]]);
        assert!(notes.is_empty());
    }
}
