"""Templates (design notes §4): expressions, SQL conditions, the decision table, template rows
and their loading, lint and history."""
