"""Several plants, one template authority (issue 33; docs/design.md §12): the head office publishes
its released template versions and the records they run on by PostgreSQL's logical replication,
each plant subscribes to them and publishes its own history back (`engine plant publish|subscribe|status`)."""
