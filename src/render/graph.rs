//! A small render graph: named nodes that declare which named resources they read and write,
//! ordered so every reader runs after the writers of what it reads. Persistent resources owned
//! by a node (the shadow map) are imported by name so other nodes can declare reads of them.

use thiserror::Error;

use crate::render::frame::FrameContext;

/// A pass in the graph.
pub trait RenderNode: Send + Sync {
    /// Unique node name (also used for GPU timings).
    fn name(&self) -> &'static str;
    /// Resources this node reads.
    fn reads(&self) -> &'static [&'static str];
    /// Resources this node writes.
    fn writes(&self) -> &'static [&'static str];
    /// Records the node's GPU work.
    fn record(&mut self, ctx: &mut FrameContext<'_>, encoder: &mut wgpu::CommandEncoder);
}

/// A graph that cannot run.
#[derive(Debug, Error, PartialEq, Eq)]
#[non_exhaustive]
pub enum GraphError {
    /// A node reads a resource nothing writes or imports.
    #[error("node `{node}` reads `{resource}`, which no node writes and nothing imports")]
    UnknownResource {
        /// Reading node.
        node: &'static str,
        /// Missing resource.
        resource: &'static str,
    },
    /// Nodes read each other's outputs in a loop.
    #[error("render graph has a cycle through node `{0}`")]
    Cycle(&'static str),
}

/// Nodes plus the execution order derived from their declarations.
#[derive(Default)]
pub struct RenderGraph {
    nodes: Vec<Box<dyn RenderNode>>,
    imported: Vec<&'static str>,
    order: Vec<usize>,
}

impl RenderGraph {
    /// Adds a node; call [`compile`](Self::compile) after the last one.
    pub fn add_node(&mut self, node: Box<dyn RenderNode>) {
        self.nodes.push(node);
        self.order.clear();
    }

    /// Declares a resource that lives outside the graph (written by earlier frames or the
    /// application), so reads of it need no writer.
    pub fn import(&mut self, resource: &'static str) {
        self.imported.push(resource);
    }

    /// Orders the nodes: a node runs after every node that writes a resource it reads.
    /// Nodes with no dependency between them keep the order they were added in.
    pub fn compile(&mut self) -> Result<(), GraphError> {
        let n = self.nodes.len();
        let mut deps: Vec<Vec<usize>> = vec![Vec::new(); n];
        for (i, node) in self.nodes.iter().enumerate() {
            for &r in node.reads() {
                let writers: Vec<usize> = (0..n)
                    .filter(|&j| j != i && self.nodes[j].writes().contains(&r))
                    .collect();
                if writers.is_empty() && !self.imported.contains(&r) && !node.writes().contains(&r) {
                    return Err(GraphError::UnknownResource {
                        node: node.name(),
                        resource: r,
                    });
                }
                deps[i].extend(writers);
            }
        }
        let mut order = Vec::with_capacity(n);
        let mut state = vec![0u8; n]; // 0 new, 1 visiting, 2 done
        fn visit(i: usize, deps: &[Vec<usize>], state: &mut [u8], order: &mut Vec<usize>) -> Result<(), usize> {
            match state[i] {
                2 => return Ok(()),
                1 => return Err(i),
                _ => {}
            }
            state[i] = 1;
            for &d in &deps[i] {
                visit(d, deps, state, order)?;
            }
            state[i] = 2;
            order.push(i);
            Ok(())
        }
        for i in 0..n {
            visit(i, &deps, &mut state, &mut order).map_err(|c| GraphError::Cycle(self.nodes[c].name()))?;
        }
        self.order = order;
        Ok(())
    }

    /// Node names in execution order.
    pub fn execution_order(&self) -> Vec<&'static str> {
        self.order.iter().map(|&i| self.nodes[i].name()).collect()
    }

    /// Records every node in order into one encoder.
    pub fn execute(&mut self, ctx: &mut FrameContext<'_>, encoder: &mut wgpu::CommandEncoder) {
        for &i in &self.order {
            self.nodes[i].record(ctx, encoder);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A node that only declares resources (never recorded in these tests).
    struct Declared {
        name: &'static str,
        reads: &'static [&'static str],
        writes: &'static [&'static str],
    }

    impl RenderNode for Declared {
        fn name(&self) -> &'static str {
            self.name
        }
        fn reads(&self) -> &'static [&'static str] {
            self.reads
        }
        fn writes(&self) -> &'static [&'static str] {
            self.writes
        }
        fn record(&mut self, _: &mut FrameContext<'_>, _: &mut wgpu::CommandEncoder) {
            unreachable!("not recorded in graph tests")
        }
    }

    fn node(
        name: &'static str,
        reads: &'static [&'static str],
        writes: &'static [&'static str],
    ) -> Box<dyn RenderNode> {
        Box::new(Declared { name, reads, writes })
    }

    #[test]
    fn readers_run_after_writers_whatever_the_insertion_order() {
        let mut graph = RenderGraph::default();
        graph.import("instances");
        graph.add_node(node("post", &["color"], &["final"]));
        graph.add_node(node("forward", &["shadow_map", "instances"], &["color"]));
        graph.add_node(node("shadow", &["instances"], &["shadow_map"]));
        graph.compile().unwrap();
        assert_eq!(graph.execution_order(), ["shadow", "forward", "post"]);
    }

    #[test]
    fn unknown_reads_and_cycles_are_errors() {
        let mut graph = RenderGraph::default();
        graph.add_node(node("forward", &["shadow_map"], &["color"]));
        assert_eq!(
            graph.compile(),
            Err(GraphError::UnknownResource {
                node: "forward",
                resource: "shadow_map"
            })
        );
        // Importing the persistent resource makes the read legal.
        graph.import("shadow_map");
        graph.compile().unwrap();

        let mut cyclic = RenderGraph::default();
        cyclic.add_node(node("a", &["y"], &["x"]));
        cyclic.add_node(node("b", &["x"], &["y"]));
        assert!(matches!(cyclic.compile(), Err(GraphError::Cycle(_))));
    }
}
