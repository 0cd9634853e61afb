//! The elimination order of a forest: each tree searched breadth-first from its root, then
//! reversed, so that every vertex comes before its parent (leaves first), with each vertex's
//! parent and the label of their edge. Used where a symmetric matrix's off-diagonal pattern is
//! a forest and its LDLᵀ factorization has no fill.

/// Vertices leaves first, and each vertex's parent with the label of the edge to it.
pub(crate) type ForestOrder<T> = (Vec<usize>, Vec<Option<(usize, T)>>);

/// The vertices of the graph on 0..n whose edges v–w are listed by `neighbours(v)` as
/// (w, label) from both ends, leaves first, and each vertex's parent with the label of the
/// edge to it (None for a root). Each tree is rooted at its first vertex in `roots` followed by
/// 0..n (out-of-range roots are skipped). None when a vertex is reached twice: the graph has a
/// cycle (or an edge listed twice).
pub(crate) fn leaves_first<'a, T: Copy + 'a>(
    n: usize,
    roots: impl Iterator<Item = usize>,
    neighbours: impl Fn(usize) -> &'a [(usize, T)],
) -> Option<ForestOrder<T>> {
    let mut parent: Vec<Option<(usize, T)>> = vec![None; n];
    let mut seen = vec![false; n];
    let mut order = Vec::with_capacity(n);
    for root in roots.chain(0..n).filter(|&r| r < n) {
        if seen[root] {
            continue;
        }
        seen[root] = true;
        let mut next = order.len();
        order.push(root);
        while next < order.len() {
            let vertex = order[next];
            next += 1;
            for &(other, label) in neighbours(vertex) {
                if parent[vertex].is_some_and(|(up, _)| up == other) {
                    continue;
                }
                if seen[other] {
                    return None;
                }
                seen[other] = true;
                parent[other] = Some((vertex, label));
                order.push(other);
            }
        }
    }
    order.reverse();
    Some((order, parent))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn adjacency(n: usize, edges: &[(usize, usize)]) -> Vec<Vec<(usize, usize)>> {
        let mut lists = vec![Vec::new(); n];
        for (e, &(i, j)) in edges.iter().enumerate() {
            lists[i].push((j, e));
            lists[j].push((i, e));
        }
        lists
    }

    /// Random forests (each vertex joined to an earlier one or left a root), relabelled at
    /// random: every vertex appears once, after all its children, and its parent edge is one of
    /// its own; adding any edge inside a tree makes a cycle, which is refused.
    #[test]
    fn random_forests_are_ordered_leaves_first_and_cycles_refused() {
        let mut rng = crate::testing::graded::SplitMix::new(0x9e37_79b9_7f4a_7c15);
        let mut next = |m: usize| rng.below(m);
        for _ in 0..300 {
            let n = 1 + next(40);
            let mut label: Vec<usize> = (0..n).collect();
            for i in (1..n).rev() {
                label.swap(i, next(i + 1));
            }
            let mut edges = Vec::new();
            for v in 1..n {
                if next(5) != 0 {
                    edges.push((label[v], label[next(v)]));
                }
            }
            let lists = adjacency(n, &edges);
            let root = next(n + 2);
            let (order, parent) = leaves_first(n, std::iter::once(root), |v| &lists[v]).expect("a forest");
            let mut position = vec![usize::MAX; n];
            for (k, &v) in order.iter().enumerate() {
                assert_eq!(position[v], usize::MAX, "vertex {v} twice");
                position[v] = k;
            }
            assert!(position.iter().all(|&p| p < n));
            let with_parent = parent.iter().filter(|p| p.is_some()).count();
            assert_eq!(with_parent, edges.len());
            for (v, p) in parent.iter().enumerate() {
                if let Some((up, e)) = *p {
                    assert!(position[v] < position[up]);
                    assert!(edges[e] == (v, up) || edges[e] == (up, v));
                }
            }
            if root < n {
                assert!(parent[root].is_none());
            }
            // An edge between a vertex and its grandparent closes a cycle.
            if let Some(v) = (0..n).find(|&v| parent[v].and_then(|(up, _)| parent[up]).is_some()) {
                let grand = parent[parent[v].expect("parent").0].expect("grandparent").0;
                let mut closed = edges.clone();
                closed.push((v, grand));
                let lists = adjacency(n, &closed);
                assert!(leaves_first(n, std::iter::empty(), |v| &lists[v]).is_none());
            }
        }
    }
}
